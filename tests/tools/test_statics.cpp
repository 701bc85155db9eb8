// Statics by adaptive dynamic relaxation (docs/theory.md §22): the CMAME 2017 §5.1 bi-material bar
// against its piecewise-linear solution, a plate in tension against a long damped dynamic run of
// the same scene and against σL/E, load steps, the energy ledger, fracture between relaxations (a
// bar, a notched plate), and what a static scene refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/physics/loads.hpp"
#include "tests/support/statics.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

using test::tension_plate;

/// CMAME 2017 §5.1: a 1 m bar, E1 = 1 (Δx = 0.01) on the left half, E2 = 2 (Δx = 0.005) on the
/// right, three points held at each end, the right ones moved by Δs = 1e-4. Linear partial volumes
/// make the bar's modulus E (with none, 3 neighbours a side at δ = 3.015Δx give 12Δx²/δ² E =
/// 1.32 E).
std::string bimaterial_bar(const std::string& model) {
  return "name: bar\ndimension: 1\narea: 1.0\nmaterials:\n  soft: {E: 1.0, rho: 1.0}\n"
         "  stiff: {E: 2.0, rho: 1.0}\nbody:\n"
         "  - {shape: box, min: [0.0], max: [0.5], spacing: 0.01, material: soft}\n"
         "  - {shape: box, min: [0.5], max: [1.0], spacing: 0.005, material: stiff}\n"
         "partial_volume: linear\nmodel: " +
         model +
         "\nboundary_conditions:\n"
         "  - region: {shape: box, min: [0.0], max: [0.03]}\n    fixed: true\n"
         "  - region: {shape: box, min: [0.985], max: [1.0]}\n    displacement: {x: 1.0e-4}\n"
         "solver: {type: static, tolerance: 1.0e-8}\ntime: {steps: 1}\n";
}

/// The least-squares slope of u over the particles with lo < X < hi.
double slope(const ParticleStore& p, double lo, double hi) {
  double n = 0, sx = 0, su = 0, sxx = 0, sxu = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.reference_position[0][i], u = p.displacement[0][i];
    if (x <= lo || x >= hi) continue;
    n += 1, sx += x, su += u, sxx += x * x, sxu += x * u;
  }
  return (n * sxu - sx * su) / (n * sxx - sx * sx);
}

struct BarResult {
  double soft_strain, stiff_strain, reaction_left, reaction_right;
  std::vector<double> sections;  ///< force across x = 0.25, 0.5 (the interface), 0.75
};

BarResult solve_bar(const std::string& model) {
  const auto scene = scene::parse_scene(bimaterial_bar(model), "bar.yaml");
  auto sim = scene::build_simulation(scene);
  sim->step();
  const auto& p = sim->particles();
  // Away from the held ends and the interface by two coarse horizons.
  const double reach = 2 * 3.015 * 0.01;
  const auto left = reaction_force(sim->loads(), p, 0);
  const auto right = reaction_force(sim->loads(), p, 1);
  std::vector<double> sections;
  for (const double at : {0.25, 0.5, 0.75}) sections.push_back(sim->force_across(0, at)[0]);
  return {slope(p, 0.03 + reach, 0.5 - reach), slope(p, 0.5 + reach, 0.985 - reach), left[0],
          right[0], sections};
}

// Dual horizons: the strain halves where E doubles and the force is E ε on both sides (the
// analytic solution's σ = E1 ε1 = E2 ε2); the reactions balance.
TEST(Statics, DualHorizonBimaterialBarIsPiecewiseLinear) {
  const auto r = solve_bar("dual-horizon");
  std::printf("dual horizon: ε1 %.6e, ε2 %.6e, ratio %.5f; E1 ε1 %.6e, E2 ε2 %.6e, R %.6e\n",
              r.soft_strain, r.stiff_strain, r.soft_strain / r.stiff_strain, r.soft_strain,
              2 * r.stiff_strain, r.reaction_right);
  EXPECT_NEAR(r.soft_strain / r.stiff_strain, 2.0, 0.01);
  EXPECT_NEAR(r.soft_strain / r.reaction_right, 1.0, 0.01);
  EXPECT_NEAR(2 * r.stiff_strain / r.reaction_right, 1.0, 0.01);
  EXPECT_NEAR(r.reaction_left / r.reaction_right, -1.0, 1e-6);  // 100 × the tolerance: Σ vs |.|
  // The sectional force (the pull across a cut) is the same everywhere, the interface included.
  for (const double f : r.sections) EXPECT_NEAR(f / r.reaction_right, 1.0, 1e-6);
}

// One constant horizon (the coarse one) for both halves, each bond the owner's E (the paper's
// Case I): a pair across the material interface pulls its two ends with different forces, so the
// sectional force jumps there (the reactions differ by about half) and the strains are not E's.
TEST(Statics, ConstantHorizonBimaterialBarMissesIt) {
  const auto r = solve_bar("constant-horizon");
  std::printf("constant horizon: ε1 %.6e, ε2 %.6e, ratio %.5f; E1 ε1 / R %.4f, E2 ε2 / R %.4f\n",
              r.soft_strain, r.stiff_strain, r.soft_strain / r.stiff_strain,
              r.soft_strain / r.reaction_right, 2 * r.stiff_strain / r.reaction_right);
  const double worst = std::max(std::abs(r.soft_strain / r.reaction_right - 1.0),
                                std::abs(2 * r.stiff_strain / r.reaction_right - 1.0));
  EXPECT_GT(worst, 0.2);
  EXPECT_GT(std::abs(r.reaction_left / r.reaction_right + 1.0), 0.2);
  // The force across a cut, Σ V f over the part before it, is the left support's pull at every
  // cut (each free particle is in equilibrium); the right support pulls 1/0.54 as hard: the
  // pairs across the material interface put an unbalanced (ghost) force on the bar.
  std::printf("constant horizon: force across x = 0.25, 0.5, 0.75: %.6e %.6e %.6e\n", r.sections[0],
              r.sections[1], r.sections[2]);
  for (const double f : r.sections) EXPECT_NEAR(f / -r.reaction_left, 1.0, 1e-6);
}

struct PlateCase {
  const char* name;
  const char* model;
  double nu;
  /// How far the centre line's strain may be from σ/E: bond-based PD has no surface correction,
  /// so the plate's free edges (three of its twenty rows each) are softer and its middle strains
  /// more (measured 1.177).
  double strain_tolerance;
};

class StaticPlate : public ::testing::TestWithParam<PlateCase> {};

// ADR's equilibrium against the end of a long damped dynamic run of the same scene (mass-
// proportional damping at about twice the lowest frequency, velocity Verlet): the same
// displacements to 1e-4 of the largest; and the strain along the centre line against σ/E.
TEST_P(StaticPlate, EqualsALongDampedDynamicRunAndPullsAsSigmaOverE) {
  const auto c = GetParam();
  auto statics = scene::build_simulation(scene::parse_scene(
      tension_plate("solver: {type: static, tolerance: 1.0e-8}\ntime: {steps: 1}\n", c.model, c.nu),
      "static.yaml"));
  statics->step();
  auto dynamics = scene::build_simulation(scene::parse_scene(
      tension_plate("time: {steps: 1, safety: 0.9}\n", c.model, c.nu), "dynamic.yaml"));
  // The lowest mode of a clamped–free plate of length L: ω ≈ (π/2) sqrt(E/ρ) / L.
  const double lowest = 0.5 * M_PI * std::sqrt(200e9 / 7850) / 0.085;
  auto& p = dynamics->particles();
  const double keep = std::exp(-2.0 * lowest * dynamics->dt());
  for (int k = 0; k < 12000; ++k) {
    dynamics->step();
    for (int a = 0; a < 2; ++a)
      for (auto& v : p.velocity[a]) v *= keep;
  }
  const auto& q = statics->particles();
  double largest = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i)
    for (int a = 0; a < 2; ++a) {
      largest = std::max(largest, std::abs(q.displacement[a][i]));
      difference = std::max(difference, std::abs(q.displacement[a][i] - p.displacement[a][i]));
    }
  // The strain along y = 0.05 between x = 0.04 and 0.07 (away from the clamp and the load).
  double strain = 0.0;
  {
    double n = 0, sx = 0, su = 0, sxx = 0, sxu = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      const double x = q.reference_position[0][i], y = q.reference_position[1][i];
      if (std::abs(y - 0.0475) > 1e-9 || x < 0.04 || x > 0.07) continue;
      const double u = q.displacement[0][i];
      n += 1, sx += x, su += u, sxx += x * x, sxu += x * u;
    }
    strain = (n * sxu - sx * su) / (n * sxx - sx * sx);
  }
  const auto& r = statics->last_relaxation();
  std::printf("%s: %lld iterations; |u_static - u_damped| / max|u| = %.2e; strain / (σ/E) %.4f\n",
              c.name, static_cast<long long>(r.iterations), difference / largest, strain / 1e-3);
  EXPECT_LT(difference / largest, 1e-4);
  EXPECT_NEAR(strain / 1e-3, 1.0, c.strain_tolerance);
}

INSTANTIATE_TEST_SUITE_P(
    Models, StaticPlate,
    ::testing::Values(PlateCase{"bond-based", "dual-horizon", 1.0 / 3.0, 0.2},
                      PlateCase{"ordinary state-based ν = 0.25",
                                "{family: ordinary-state, horizon: dual-horizon}", 0.25, 0.02},
                      PlateCase{"correspondence ν = 0.25",
                                "{family: correspondence, horizon: dual-horizon}", 0.25, 0.03}),
    [](const auto& info) {
      return std::string(info.index == 0 ? "BondBased" : info.index == 1 ? "Ordinary" : "Nosb");
    });

// Load steps: the same linear plate reached in four steps is the one-step answer (to the
// tolerance), the history's work equals the strain energy (Clapeyron, trapezoidal work exact for a
// linear response), and each step relaxes from the last.
TEST(Statics, LoadStepsReachTheSameStateAndTheWorkIsTheStrainEnergy) {
  const auto model = "{family: ordinary-state, horizon: dual-horizon}";
  auto once = scene::build_simulation(scene::parse_scene(
      tension_plate("solver: {type: static, tolerance: 1.0e-9}\ntime: {steps: 1}\n", model, 0.25),
      "one.yaml"));
  once->step();
  auto stepped = scene::build_simulation(scene::parse_scene(
      tension_plate("solver: {type: static, tolerance: 1.0e-9}\ntime: {steps: 4}\n", model, 0.25),
      "four.yaml"));
  std::vector<double> loads;
  for (int k = 0; k < 4; ++k) {
    stepped->step();
    loads.push_back(stepped->load_factor());
  }
  EXPECT_EQ(loads, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
  double largest = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < once->particles().size(); ++i) {
    const double a = once->particles().displacement[0][i];
    largest = std::max(largest, std::abs(a));
    difference = std::max(difference, std::abs(a - stepped->particles().displacement[0][i]));
  }
  EXPECT_LT(difference / largest, 1e-6);
  const auto e = stepped->energies();
  std::printf("4 load steps: strain energy %.9e J, work %.9e J\n", e.strain, e.external_work);
  EXPECT_NEAR(e.strain / e.external_work, 1.0, 1e-3);
}

// Fracture between relaxations: a bar pulled to 0.5 of its bonds' critical stretch keeps every
// bond; pulled to 1.5 of it, bonds break round after round until it has parted and carries no
// force.
TEST(Statics, BondsBreakBetweenRelaxationsUntilTheBarParts) {
  const auto pulled = [](double fraction) {
    auto text = bimaterial_bar("dual-horizon");
    text.replace(text.find("{E: 1.0, rho: 1.0}"), 18, "{E: 1.0, rho: 1.0, G0: 1.0e-6}");
    text.replace(text.find("{E: 2.0, rho: 1.0}"), 18, "{E: 2.0, rho: 1.0, G0: 1.0e-6}");
    text += "effects: {fracture: true}\n";
    auto sim = scene::build_simulation(scene::parse_scene(text, "bar.yaml"));
    // The bar's mean strain at the break: the softest bonds' critical stretch.
    double s0 = HUGE_VAL;
    for (const double s : sim->critical_stretch()) s0 = std::min(s0, s);
    auto held = scene::parse_scene(text, "bar.yaml");
    held.boundary_conditions[1].bc.displacement[0] = fraction * s0 * 0.95;
    sim = scene::build_simulation(held);
    sim->step();
    const auto r = reaction_force(sim->loads(), sim->particles(), 1);
    std::printf("pulled by %.2f s0 L: %lld bonds broken in %d relaxations, reaction %.3e\n",
                fraction, static_cast<long long>(sim->broken_bonds()),
                sim->last_relaxation().rounds, r[0]);
    return std::pair{sim->broken_bonds(), r[0]};
  };
  EXPECT_EQ(pulled(0.5).first, 0);  // the soft half strains 4/3 of the mean: 0.67 s0
  const auto [broken, reaction] = pulled(1.5);
  EXPECT_GT(broken, 0);
  EXPECT_EQ(reaction, 0.0);
}

// Quasi-static crack growth: a 20 mm glass plate with a 5 mm edge notch, pulled in ten load
// steps, is elastic (the reaction linear in the load) until its notch tip breaks, then the crack
// runs along the notch's line and the plate parts (the reaction falls to round-off of the load
// it carried, which the relaxation's reference keeps: docs/theory.md §22).
TEST(Statics, NotchedPlateCracksAlongItsNotchAndParts) {
  const std::string text =
      "name: notched\ndimension: 2\nplane: stress\nthickness: 0.001\nmaterials:\n"
      "  glass: {E: 72.0e9, rho: 2440, G0: 3.8}\nbody:\n"
      "  - {shape: box, min: [0, 0], max: [0.02, 0.02], spacing: 0.0005, material: glass}\n"
      "cracks:\n  - [[0.0, 0.01], [0.005, 0.01]]\npartial_volume: linear\n"
      "boundary_conditions:\n"
      "  - {region: {shape: box, min: [0, 0], max: [0.02, 0.0015]}, fixed: true}\n"
      "  - {region: {shape: box, min: [0, 0.0185], max: [0.02, 0.02]}, displacement: {y: 3.0e-6}}\n"
      "no_fail:\n  - {shape: box, min: [0, 0], max: [0.02, 0.003]}\n"
      "  - {shape: box, min: [0, 0.017], max: [0.02, 0.02]}\n"
      "effects: {fracture: true}\nsolver: {type: static, tolerance: 1.0e-5}\ntime: {steps: 10}\n";
  const auto scene = scene::parse_scene(text, "notched.yaml");
  auto sim = scene::build_simulation(scene);
  std::vector<double> reaction;
  std::vector<std::int64_t> broken;
  for (int k = 0; k < 10; ++k) {
    sim->step();
    reaction.push_back(reaction_force(sim->loads(), sim->particles(), 1)[1]);
    broken.push_back(sim->broken_bonds());
  }
  for (int k = 0; k < 10; ++k)
    std::printf("load factor %.1f: reaction %.6g N, %lld bonds broken\n", 0.1 * (k + 1),
                reaction[k], static_cast<long long>(broken[k]));
  EXPECT_EQ(broken[4], 0);
  for (int k = 1; k < 5; ++k) EXPECT_NEAR(reaction[k] / reaction[0], k + 1.0, 1e-4 * (k + 1));
  EXPECT_GT(broken.back(), 0);
  const double peak = *std::max_element(reaction.begin(), reaction.end());
  EXPECT_LT(std::abs(reaction.back()), 1e-3 * peak);
  // Every particle that lost a fifth of its bonds lies within a horizon of the notch's line.
  const auto& p = sim->particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.damage[i] > 0.2) {
      EXPECT_NEAR(p.reference_position[1][i], 0.01, 0.0015) << i;
    }
}

// Bad input: what a static scene cannot mean is refused at its key.
TEST(Statics, SceneRefusesWhatAStaticRunCannotMean) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      scene::parse_scene(text, "s.yaml");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  const auto plate = [](const std::string& extra, const std::string& time = "{steps: 1}") {
    return tension_plate("solver: static\ntime: " + time + "\n" + extra, "dual-horizon", 1.0 / 3.0);
  };
  refused(plate("", "{end: 1.0}"),
          "s.yaml:18: time.end: a static run counts load steps, not seconds");
  refused(plate("", "{steps: 1, dt: 1.0e-7}"), "time.dt: a static run has no time step");
  refused(plate("", "{steps: 1, multirate: true}"), "time levels are a dynamic scheme");
  auto velocity = plate("");
  velocity.replace(velocity.find("fixed: true"), 11, "velocity: {x: 1.0}");
  refused(velocity, "boundary_conditions.0.velocity: a static run holds displacements");
  refused(plate("").replace(plate("").find("solver: static"), 14, "solver: {type: statik}"),
          "solver.type");
  refused(plate("").replace(plate("").find("solver: static"), 14,
                            "solver: {type: static, tolerance: 2.0}"),
          "solver.tolerance: tolerance is a fraction of the load");
}

}  // namespace
}  // namespace dhpd
