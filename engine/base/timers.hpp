// Wall-clock time per phase of a run (search, bonds, forces, fracture, integrate, output, ...).
#pragma once
#include <array>
#include <chrono>
#include <string_view>

namespace dhpd {

enum class Phase { Search, Forces, Fracture, Integrate, Loads, Diagnostics, Output, Refine, Count };

constexpr std::string_view phase_name(Phase p) {
  constexpr std::array<std::string_view, static_cast<int>(Phase::Count)> names = {
      "search_and_bonds", "forces", "fracture", "integrate", "loads",
      "diagnostics",      "output", "refine"};
  return names[static_cast<int>(p)];
}

class PhaseTimers {
 public:
  double seconds(Phase p) const { return seconds_[static_cast<int>(p)]; }
  void add(Phase p, double s) { seconds_[static_cast<int>(p)] += s; }

  /// RAII scope that adds its lifetime to a phase.
  class Scope {
   public:
    Scope(PhaseTimers& t, Phase p) : t_(t), p_(p), start_(std::chrono::steady_clock::now()) {}
    ~Scope() {
      t_.add(p_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    PhaseTimers& t_;
    Phase p_;
    std::chrono::steady_clock::time_point start_;
  };
  Scope scope(Phase p) { return Scope(*this, p); }

 private:
  std::array<double, static_cast<int>(Phase::Count)> seconds_{};
};

}  // namespace dhpd
