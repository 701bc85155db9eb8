// The 2D wave test of IJNME 2016 §5.1 (cases/wave_plate_2d.yaml): a plane pulse crossing a 1 mm /
// 0.5 mm resolution jump. What comes back into the coarse part is measured against the same plate
// at uniform 1 mm (identical particles there, same dt): dual horizons reflect little, the
// classical variable-horizon model (ghost forces) much more.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

/// The case with the pulse centred at x = 25 mm (so its right half reaches the jump at 40 mm)
/// and `extra` overrides.
std::unique_ptr<Simulation> plate(std::vector<std::string> extra) {
  extra.push_back("initial_conditions.0.gaussian.center=[0.025,0.0]");
  std::vector<scene::Override> sets;
  for (const auto& s : extra) sets.push_back(scene::parse_override(s));
  return build_simulation(
      scene::load_scene(std::string(DHPD_SOURCE_DIR) + "/cases/wave_plate_2d.yaml", sets));
}

/// The same, run for `steps` steps of `dt`.
std::unique_ptr<Simulation> run_plate(std::vector<std::string> extra, double dt, int steps) {
  extra.push_back(fmt::format("time.dt={:.17g}", dt));
  auto sim = plate(extra);
  sim->run_steps(steps);
  return sim;
}

/// Largest |u_x − u_x,ref| over particles with x < 30 mm, over the incident amplitude 1e-4 m
/// (half of the 2e-4 m initial bump travels each way).
double reflected(const Simulation& sim, const Simulation& ref) {
  std::map<std::pair<long, long>, double> ref_u;
  const auto& r = ref.particles();
  auto key = [](const ParticleStore& p, std::size_t i) {
    return std::pair{std::lround(p.reference_position[0][i] * 1e5),
                     std::lround(p.reference_position[1][i] * 1e5)};
  };
  for (std::size_t i = 0; i < r.size(); ++i) ref_u[key(r, i)] = r.displacement[0][i];
  const auto& p = sim.particles();
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.reference_position[0][i] >= 0.03) continue;
    worst = std::max(worst, std::abs(p.displacement[0][i] - ref_u.at(key(p, i))));
  }
  return worst / 1e-4;
}

TEST(WavePlate, DualHorizonReflectsLittleAtTheResolutionJump) {
  // The mixed plate's stable step, for all three runs (the classical variable-horizon model's is
  // the per-particle bound, docs/theory.md §9); 0.045 s puts the reflected part (if any) back in
  // x < 30 mm and the transmitted pulse inside the fine zone.
  const double dt =
      0.8 * std::min(plate({})->critical_dt(), plate({"model=classical-variable"})->critical_dt());
  const int steps = static_cast<int>(std::lround(0.045 / dt));
  const auto coarse = run_plate({"body.1.spacing=0.001"}, dt, steps);
  const double dh = reflected(*run_plate({}, dt, steps), *coarse);
  const double classical = reflected(*run_plate({"model=classical-variable"}, dt, steps), *coarse);
  std::printf("wave plate 2D: reflected/incident %.2f %% (dual-horizon), %.2f %% (classical)\n",
              100 * dh, 100 * classical);
  EXPECT_LT(dh, 0.035);
  EXPECT_GT(classical, 3.0 * dh);
}

}  // namespace
}  // namespace dhpd
