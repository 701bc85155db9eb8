// IJNME 2016 §5.1 as the paper runs it (cases/wave_plate_2d_state.yaml): ordinary state-based PD,
// ν = 0, δ = 3Δx, Δt = 5e-4 s. The L2 error of u along the centre line (eq. 58) against the 1D
// solution, for models A (uniform 1 mm), B (classical variable horizon) and C (dual horizon), at
// the steps of the paper's Table 3, printed beside it. Dual horizons are as good as the uniform
// plate; the classical variable-horizon model's ghost forces scatter the pulse.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

constexpr std::array<int, 4> kSteps{100, 200, 650, 990};
using Errors = std::array<double, 4>;

/// The analytic displacement of the free-free bar: ½[g(x − t) + g(x + t)], g the initial pulse
/// mirrored at both ends (period 0.2 m), wave speed 1 m/s.
double analytic(double x, double t) {
  auto g = [](double s) {
    s = std::fmod(std::fmod(s, 0.2) + 0.2, 0.2);
    if (s > 0.1) s = 0.2 - s;
    return 2e-4 * std::exp(-(s / 0.01) * (s / 0.01));
  };
  return 0.5 * (g(x - t) + g(x + t));
}

/// Eq. 58 over the particles of the centre line (the row or rows nearest y = 0).
double l2_error(const Simulation& sim) {
  const auto& p = sim.particles();
  double err = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(p.reference_position[1][i]) > 0.6e-3) continue;
    const double ua = analytic(p.reference_position[0][i], sim.time());
    const double dx = p.displacement[0][i] - ua, dy = p.displacement[1][i];
    err += (dx * dx + dy * dy) * p.volume[i];
    norm += ua * ua * p.volume[i];
  }
  return std::sqrt(err / norm);
}

Errors run_model(const std::vector<std::string>& extra) {
  std::vector<scene::Override> sets;
  for (const auto& s : extra) sets.push_back(scene::parse_override(s));
  auto sim = build_simulation(
      scene::load_scene(std::string(DHPD_SOURCE_DIR) + "/cases/wave_plate_2d_state.yaml", sets));
  Errors out{};
  int done = 0;
  for (std::size_t k = 0; k < kSteps.size(); ++k) {
    sim->run_steps(kSteps[k] - done);
    done = kSteps[k];
    out[k] = l2_error(*sim);
  }
  return out;
}

TEST(WavePlateState, DualHorizonAsUniformClassicalVariableScatters) {
  const Errors a = run_model({"body.1.spacing=0.001"});
  const Errors b = run_model({"model.horizon=classical-variable"});
  const Errors c = run_model({});
  const Errors paper[3] = {{0.0410, 0.0452, 0.1277, 0.2498},
                           {0.1149, 0.1738, 0.7638, 1.3233},
                           {0.0447, 0.0500, 0.1253, 0.2871}};
  const char* names[3] = {"A (uniform)", "B (classical variable)", "C (dual horizon)"};
  const Errors* ours[3] = {&a, &b, &c};
  std::printf("L2 error along the centre line, ours | IJNME 2016 Table 3\n");
  std::printf(
      "model                    step 100        step 200        step 650        step 990\n");
  for (int m = 0; m < 3; ++m) {
    std::string line = fmt::format("{:<24}", names[m]);
    for (std::size_t k = 0; k < kSteps.size(); ++k)
      line += fmt::format(" {:.4f}|{:.4f}  ", (*ours[m])[k], paper[m][k]);
    std::printf("%s\n", line.c_str());
  }
  for (std::size_t k = 0; k < kSteps.size(); ++k) {
    // Dual horizons as good as uniform: within 15 %, or 0.01 where both are far below the paper's
    // (step 200: 0.021 against 0.015, the paper's 0.050 and 0.045).
    EXPECT_LE(c[k], std::max(1.15 * a[k], a[k] + 0.01)) << "step " << kSteps[k];
    if (kSteps[k] >= 200) {
      EXPECT_GE(b[k], 2.5 * c[k]) << "step " << kSteps[k];
    }
  }
  // The uniform plate's own accuracy: the pulse arrives (a missing shell of bonds, or a wrong
  // modulus, shifts it by millimetres and the error past 0.5 by step 200).
  EXPECT_LT(a[1], 0.1);
}

// The correspondence family on the same test (docs/theory.md §21): dual horizons as good as the
// uniform plate, and the horizon-size paper's ranking for it, δ = 2Δx better than 3Δx.
TEST(WavePlateState, CorrespondenceDualHorizonAndItsBestHorizon) {
  const std::string family = "model.family=correspondence";
  const Errors a2 = run_model({family, "horizon.factor=2.015", "body.1.spacing=0.001"});
  const Errors c2 = run_model({family, "horizon.factor=2.015"});
  const Errors a3 = run_model({family, "horizon.factor=3.0", "body.1.spacing=0.001"});
  std::printf("correspondence, L2 at steps 100 / 200 / 650 / 990:\n");
  for (const auto& [name, e] :
       {std::pair{"A, δ = 2Δx", a2}, {"C, δ = 2Δx", c2}, {"A, δ = 3Δx", a3}})
    std::printf("  %-12s %.4f %.4f %.4f %.4f\n", name, e[0], e[1], e[2], e[3]);
  for (std::size_t k = 0; k < kSteps.size(); ++k) {
    EXPECT_LE(c2[k], std::max(1.15 * a2[k], a2[k] + 0.01)) << "step " << kSteps[k];
    if (kSteps[k] >= 650) {
      EXPECT_LT(a2[k], a3[k]) << "step " << kSteps[k];
    }
  }
}

}  // namespace
}  // namespace dhpd
