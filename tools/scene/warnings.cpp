// Warnings for legal scenes that are probably not what their author meant.
#include "tools/scene/warnings.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>

#include "engine/discretization/neighbor_search.hpp"

namespace dhpd::scene {

namespace {

std::string at(const Location& w) {
  return fmt::format("{}:{}: {}", w.file, w.line, w.path);
}

/// Whether some pair of particles within a horizon of each other has its segment across the crack:
/// the crack removed at least one bond. Only particles within a horizon of the crack's bounding
/// box are asked, and the search stops at the first crossing.
bool cuts_a_bond(const geometry::Crack& crack, const ParticleStore& p,
                 const NeighborSearch& search) {
  const int dim = p.dim();
  geometry::Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& c : crack.points)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
  std::vector<std::int32_t> near;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto x = point_of(p.reference_position, i);
    bool close = true;
    for (int a = 0; a < dim; ++a)
      close = close && x[a] >= lo[a] - p.horizon[i] && x[a] <= hi[a] + p.horizon[i];
    if (!close) continue;
    search.within(i, p.horizon[i], near);
    for (const auto j : near)
      if (geometry::crosses(crack, x, point_of(p.reference_position, static_cast<std::size_t>(j)),
                            dim))
        return true;
  }
  return false;
}

bool holds_a_particle(const geometry::Shape& region, const ParticleStore& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (region.contains(point_of(p.reference_position, i), p.dim())) return true;
  return false;
}

}  // namespace

std::vector<std::string> scene_warnings(const Scene& s, const Simulation& sim,
                                        std::int64_t planned_steps) {
  std::vector<std::string> out;
  const auto& p = sim.particles();
  if (!s.cracks.empty()) {
    const NeighborSearch search(p.reference_position, p.dim());
    for (const auto& c : s.cracks)
      if (!cuts_a_bond(c.crack, p, search))
        out.push_back(
            fmt::format("{}: this pre-crack cuts no bond (it lies outside the body or "
                        "along its edge): it changes nothing",
                        at(c.where)));
  }
  for (const auto& r : s.no_fail)
    if (!holds_a_particle(r.shape, p))
      out.push_back(fmt::format("{}: this no-fail region holds no particle", at(r.where)));
  for (const auto& r : s.material_regions)
    if (!holds_a_particle(r.region, p))
      out.push_back(fmt::format("{}: this material region holds no particle", at(r.where)));
  if (planned_steps > kManySteps) {
    const double rows =
        static_cast<double>(planned_steps) / static_cast<double>(s.output.history_every);
    out.push_back(fmt::format(
        "{}:{}: time: {} steps of {:.3g} s planned (more than {}): history.csv alone would grow to "
        "about {:.3g} GB; is the end time in seconds?",
        s.time.where.file, s.time.where.line, planned_steps, sim.dt(), kManySteps,
        rows * 250.0 / 1e9));
  }
  return out;
}

}  // namespace dhpd::scene
