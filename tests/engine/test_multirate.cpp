// Multi-rate stepping (docs/theory.md §19): a fine patch in a coarse body steps at two rates with
// linear and angular momentum exact to round-off while bonds break (naive subcycling with
// interpolated coarse positions drifts far above that); one level is today's velocity Verlet bit
// for bit; the bonds evaluated per dt₀ are Σ_ℓ 2^ℓ × (bonds at level ℓ); the energy of an elastic
// run does not drift; the error falls with dt₀².
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"

namespace dhpd {
namespace {

using geometry::Box;

/// A body of `cells` coarse cells a side (spacing h) with a patch of half spacing in its middle
/// (`margin` coarse cells from each side; default: its middle third), linear β. `g0` 0: elastic.
SimulationSetup patch_body(int dim, int cells, double g0, int margin = -1) {
  SimulationSetup s;
  s.section = {dim, PlaneMode::Stress, dim == 2 ? 1e-3 : 1.0, dim == 1 ? 1e-6 : 1.0};
  s.materials = {{72e9, 2440, g0}};
  s.partial_volume = PartialVolume::Linear;
  const double h = 1e-3, size = cells * h;
  const double lo = (margin >= 0 ? margin : std::floor(cells / 3.0)) * h, hi = size - lo;
  Vec3 body_max{size, dim > 1 ? size : 0.0, dim > 2 ? size : 0.0};
  Vec3 patch_min{lo, dim > 1 ? lo : 0.0, dim > 2 ? lo : 0.0};
  Vec3 patch_max{hi, dim > 1 ? hi : 0.0, dim > 2 ? hi : 0.0};
  s.points = geometry::fill_lattice(
      {{Box{{0, 0, 0}, body_max}, h, 0}, {Box{patch_min, patch_max}, 0.5 * h, 0}}, dim);
  s.effects.fracture = g0 > 0.0;
  s.multirate = true;
  return s;
}

struct Momenta {
  Vec3 linear{0, 0, 0}, angular{0, 0, 0};
  double linear_scale = 0.0, angular_scale = 0.0;  ///< Σ |p|, Σ |y × p|
};

Momenta momenta_of(const ParticleStore& p) {
  Momenta m;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double mass = p.density[i] * p.volume[i];
    const Vec3 v{p.velocity[0][i], p.velocity[1][i], p.velocity[2][i]};
    const Vec3 y{p.position[0][i], p.position[1][i], p.position[2][i]};
    const Vec3 q = mass * v, l = geometry::cross(y, q);
    m.linear = m.linear + q;
    m.angular = m.angular + l;
    m.linear_scale += geometry::norm(q);
    m.angular_scale += geometry::norm(l);
  }
  return m;
}

/// Random initial velocities, one initial condition per particle (so the energy budget holds them).
void random_velocities(SimulationSetup& s, double speed, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-speed, speed);
  const int dim = s.section.dim;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3 x = s.points.position[i];
    const double r = 0.25 * s.points.spacing[i];
    InitialCondition ic;
    ic.region = Box{x - Vec3{r, r, r}, x + Vec3{r, r, r}};
    Vec3 v{0, 0, 0};
    for (int a = 0; a < dim; ++a) v[a] = u(rng);
    ic.velocity = v;
    s.initial_conditions.push_back(ic);
  }
}

class MultiRate : public ::testing::TestWithParam<int> {};

TEST_P(MultiRate, ConservesMomentumExactlyWhileBondsBreak) {
  const int dim = GetParam();
  auto setup = patch_body(dim, dim == 1 ? 60 : (dim == 2 ? 24 : 9), 2.0);
  random_velocities(setup, 4.0, 11 + dim);
  Simulation sim(std::move(setup));
  ASSERT_NE(sim.time_levels(), nullptr);
  EXPECT_EQ(sim.time_levels()->count(), 2);
  const auto before = momenta_of(sim.particles());
  const int steps = 2000;
  for (int k = 0; k < steps; ++k) sim.step();
  const auto after = momenta_of(sim.particles());
  EXPECT_GT(sim.broken_bonds(), 50) << "bonds break during the test";
  const double dp = geometry::norm(after.linear - before.linear) / before.linear_scale;
  const double dl = geometry::norm(after.angular - before.angular) / before.angular_scale;
  std::printf("dim %d, %d steps, %lld bonds broken: |ΔP|/Σ|p| = %.2e, |ΔL|/Σ|y×p| = %.2e\n", dim,
              steps, static_cast<long long>(sim.broken_bonds()), dp, dl);
  EXPECT_LT(dp, 1e-12);
  if (dim > 1) {
    EXPECT_LT(dl, 1e-12);
  }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, MultiRate, ::testing::Values(1, 2, 3));

/// Naive subcycling, the contrast: coarse particles (level 0) take velocity-Verlet steps of dt₀
/// with the total force; fine ones two steps of dt₀/2 with the total force, the coarse positions
/// at the half step interpolated between the step's ends. Forces of interface pairs on the two
/// ends then come from different instants.
void naive_subcycling(const Simulation& sim, ParticleStore& p, BondRows& rows, int steps) {
  const auto& level = sim.time_levels()->level;
  const double dt = sim.dt();
  const int dim = p.dim();
  const auto kick = [&](int l, double h) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (level[i] == l)
        for (int a = 0; a < dim; ++a) p.velocity[a][i] += h * p.force_density[a][i] / p.density[i];
  };
  const auto move = [&](int l, double h) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (level[i] == l)
        for (int a = 0; a < dim; ++a) {
          p.displacement[a][i] += h * p.velocity[a][i];
          p.position[a][i] = p.reference_position[a][i] + p.displacement[a][i];
        }
  };
  internal_force_density(rows, p);
  for (int k = 0; k < steps; ++k) {
    kick(0, 0.5 * dt);
    const auto start = p.position;
    move(0, dt);
    const auto end = p.position;
    for (int s = 0; s < 2; ++s) {
      kick(1, 0.25 * dt);
      move(1, 0.5 * dt);
      const double w = 0.5 * (s + 1);
      for (std::size_t i = 0; i < p.size(); ++i)
        if (level[i] == 0)
          for (int a = 0; a < dim; ++a) p.position[a][i] = (1 - w) * start[a][i] + w * end[a][i];
      internal_force_density(rows, p);
      kick(1, 0.25 * dt);
    }
    kick(0, 0.5 * dt);
  }
}

TEST(MultiRate, NaiveSubcyclingDriftsFarAboveRoundOff) {
  auto setup = patch_body(2, 24, 0.0);
  random_velocities(setup, 4.0, 13);
  Simulation sim(std::move(setup));
  ASSERT_NE(sim.time_levels(), nullptr);
  auto p = sim.particles();
  auto rows = sim.bonds();
  const auto before = momenta_of(p);
  naive_subcycling(sim, p, rows, 300);
  const auto after = momenta_of(p);
  const double dp = geometry::norm(after.linear - before.linear) / before.linear_scale;
  std::printf("naive subcycling, 300 steps: |ΔP|/Σ|p| = %.2e\n", dp);
  EXPECT_GT(dp, 1e-8) << "the momentum test can see a scheme that is not exact";
}

TEST(MultiRate, OneLevelIsVelocityVerletBitForBit) {
  auto setup = patch_body(2, 16, 0.0);
  setup.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.016, 0.016, 0}}, 1e-3, 0}}, 2);
  random_velocities(setup, 1.0, 5);
  auto off = setup;
  setup.multirate = true;
  off.multirate = false;
  Simulation on_sim(std::move(setup)), off_sim(std::move(off));
  EXPECT_EQ(on_sim.time_levels(), nullptr) << "a uniform lattice has one level";
  for (int k = 0; k < 50; ++k) on_sim.step(), off_sim.step();
  for (int a = 0; a < 2; ++a) {
    EXPECT_EQ(on_sim.particles().position[a], off_sim.particles().position[a]);
    EXPECT_EQ(on_sim.particles().velocity[a], off_sim.particles().velocity[a]);
  }
  EXPECT_EQ(on_sim.dt(), off_sim.dt());
}

TEST(MultiRate, EvaluatesEachLevelsBondsTwiceAsOftenAsTheNextCoarser) {
  Simulation sim(patch_body(2, 24, 0.0));
  const auto* t = sim.time_levels();
  ASSERT_NE(t, nullptr);
  // Brute force: the level of every own bond, max of its ends' levels.
  std::int64_t expected = 0;
  const auto& b = sim.bonds();
  std::vector<std::int64_t> per_level(static_cast<std::size_t>(t->count()), 0);
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    for_each_own_bond(b, i, [&](std::int64_t, std::size_t j) {
      ++per_level[static_cast<std::size_t>(std::max(t->level[i], t->level[j]))];
    });
  for (int l = 0; l < t->count(); ++l) expected += (std::int64_t{1} << l) * per_level[l];
  EXPECT_GT(per_level[1], 0);
  const auto start = sim.bond_updates();
  for (int k = 0; k < 7; ++k) sim.step();
  EXPECT_EQ(sim.bond_updates() - start, 7 * expected);
  EXPECT_LT(expected, 2 * static_cast<std::int64_t>(b.own_bonds))
      << "cheaper than every bond at the fine step";
}

/// The energy of an elastic run with random velocities: the mean of kinetic + strain energy over
/// the last 1,000 of 10,000 dt₀ steps against the first 1,000's.
double energy_drift(double safety) {
  auto setup = patch_body(2, 24, 0.0);
  setup.safety = safety;
  random_velocities(setup, 1.0, 21);
  Simulation sim(std::move(setup));
  EXPECT_NE(sim.time_levels(), nullptr);
  const int steps = 10000, window = 1000;
  double first = 0.0, last = 0.0;
  for (int k = 0; k < steps; ++k) {
    sim.step();
    if (k < window || k >= steps - window) {
      const auto e = sim.energies();
      (k < window ? first : last) += (e.kinetic + e.strain) / window;
    }
  }
  const double drift = std::abs(last - first) / first;
  std::printf("safety %.2f, %d dt0 steps: energy drift %.2e (first and last %d steps)\n", safety,
              steps, drift, window);
  return drift;
}

// Measured: 9.0e-5 (0.8), 4.0e-5 (0.9), 1.6e-4 (0.95): bounded at 0.95 too, not a blow-up.
TEST(MultiRate, ElasticEnergyDoesNotDriftAtSafetyPointNine) {
  EXPECT_LT(energy_drift(0.8), 1e-4);
  EXPECT_LT(energy_drift(0.9), 1e-4);
  EXPECT_LT(energy_drift(0.95), 1e-3);
}

/// u at the end of a smooth pulse's run to 40 µs with dt₀ fixed.
std::vector<double> bar_after(double dt0) {
  auto setup = patch_body(1, 120, 0.0);
  setup.multirate = true;
  setup.fixed_dt = dt0;
  InitialCondition pulse;
  pulse.region = Box{{0, 0, 0}, {0.12, 0, 0}};
  pulse.velocity = Vec3{1.0, 0, 0};
  pulse.gaussian_width = 5e-3;
  pulse.gaussian_center = Vec3{0.03, 0, 0};
  setup.initial_conditions = {pulse};
  Simulation sim(std::move(setup));
  EXPECT_NE(sim.time_levels(), nullptr);
  const auto steps = static_cast<int>(std::lround(4e-6 / dt0));
  for (int k = 0; k < steps; ++k) sim.step();
  std::vector<double> u(sim.particles().size());
  for (std::size_t i = 0; i < u.size(); ++i)
    u[static_cast<std::size_t>(sim.particles().id[i])] = sim.particles().displacement[0][i];
  return u;
}

TEST(MultiRate, ErrorFallsWithTheSquareOfTheCoarseStep) {
  const double dt = 4e-8;
  const auto reference = bar_after(dt / 64);
  const auto error = [&](double step) {
    const auto u = bar_after(step);
    double e = 0.0;
    for (std::size_t i = 0; i < u.size(); ++i) e = std::max(e, std::abs(u[i] - reference[i]));
    return e;
  };
  const double e1 = error(dt), e2 = error(dt / 2), e4 = error(dt / 4);
  std::printf("dt0 %.1e, /2, /4: errors %.3e %.3e %.3e, ratios %.2f %.2f\n", dt, e1, e2, e4,
              e1 / e2, e2 / e4);
  EXPECT_NEAR(e1 / e2, 4.0, 0.8);
  EXPECT_NEAR(e2 / e4, 4.0, 0.8);
}

/// Positions and velocities after `steps` steps of `setup` with time.multirate `choice`.
struct Outcome {
  bool levels = false;
  std::vector<double> state;
};
Outcome run_with(SimulationSetup setup, std::optional<bool> choice, int steps) {
  setup.multirate = choice;
  Simulation sim(std::move(setup));
  Outcome out{sim.time_levels() != nullptr, {}};
  sim.run_steps(steps);
  for (int a = 0; a < 2; ++a) {
    const auto& p = sim.particles();
    out.state.insert(out.state.end(), p.position[a].begin(), p.position[a].end());
    out.state.insert(out.state.end(), p.velocity[a].begin(), p.velocity[a].end());
  }
  return out;
}

TEST(MultiRateByDefault, TakesLevelsWhereTheyPayAndOneGlobalStepWhereNot) {
  // A small fine patch (8 × 8 coarse cells of a 40-cell plate): levels evaluate far fewer bonds,
  // so the default takes them, as time.multirate: true does, bit for bit.
  auto small = patch_body(2, 40, 0.0, 16);
  random_velocities(small, 1.0, 7);
  const auto by_default = run_with(small, std::nullopt, 20), forced = run_with(small, true, 20);
  EXPECT_TRUE(by_default.levels);
  EXPECT_EQ(by_default.state, forced.state);
  // A patch over all but one coarse cell at each side: the coarse rim is inside the buffer, so
  // levels would evaluate as many bonds as one global step at the fine step, or more: the
  // default keeps velocity Verlet, bit for bit with time.multirate: false (true takes levels).
  auto wide = patch_body(2, 16, 0.0, 1);
  random_velocities(wide, 1.0, 8);
  const auto wide_default = run_with(wide, std::nullopt, 20), wide_off = run_with(wide, false, 20);
  EXPECT_FALSE(wide_default.levels);
  EXPECT_TRUE(run_with(wide, true, 0).levels);
  EXPECT_EQ(wide_default.state, wide_off.state);
}

TEST(MultiRateByDefault, TooManyLevelsFallBackToOneStepUnlessLevelsWereAskedFor) {
  auto s = patch_body(2, 30, 0.0);
  s.max_time_levels = 1;
  s.multirate = std::nullopt;
  EXPECT_EQ(Simulation(s).time_levels(), nullptr);
  s.multirate = true;
  EXPECT_THROW(Simulation{s}, TimeLevelError);
}

}  // namespace
}  // namespace dhpd
