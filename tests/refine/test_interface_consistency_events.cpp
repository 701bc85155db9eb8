// Consistent level interfaces through refinement events (docs/theory.md §14): a refined zone under
// a homogeneous strain feels no interface force in 2D and 3D, and events in a loaded, fracturing
// plate keep the interfaces consistent and momentum exact (at the start: tests/engine/
// test_interface_consistency.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "tests/support/interfaces.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using geometry::Vec3;
using test::Box;
using test::forces_under;
using test::kShear;

/// Particles of the current generation within `radius` of `centre`.
std::vector<std::int32_t> ball(const Simulation& sim, const Vec3& centre, double radius) {
  std::vector<std::int32_t> out;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d2 = 0.0;
    for (int a = 0; a < p.dim(); ++a) d2 += std::pow(p.reference_position[a][i] - centre[a], 2);
    if (d2 < radius * radius) out.push_back(static_cast<std::int32_t>(i));
  }
  return out;
}

TEST(InterfaceConsistency, AHomogeneousStrainPutsNoForceOnARefinedZonesInterface) {
  for (const int dim : {2, 3}) {
    const double size = dim == 2 ? 0.04 : 0.02;
    double force[2] = {0, 0}, edge = 0.0;
    InterfaceCorrection solved;
    for (const bool correction : {false, true}) {
      auto s = test::plate(1e-3, size, size);
      if (dim == 3) {
        s.section = {3, PlaneMode::Stress, 1.0, 1.0};
        s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {size, size, size}}, 1e-3, 0}}, 3);
      }
      s.interface_correction = correction;
      Simulation sim(s);
      const auto ev =
          refine::split(sim, ball(sim, {size / 2, size / 2, size / 2}, dim == 2 ? 4e-3 : 2.6e-3));
      if (correction) solved = ev.interfaces;
      const auto f = forces_under(sim, kShear, 6e-3, size);
      force[correction] = f.inside, edge = f.edge;
    }
    std::printf(
        "%dD refined zone under a homogeneous strain: interface force %.3e N/m^3 (paper), "
        "%.3e (corrected), free faces %.3e; %zu particles, %zu factors in [%.2f, %.2f], "
        "%d iterations\n",
        dim, force[0], force[1], edge, solved.particles, solved.bonds, solved.smallest,
        solved.largest, solved.iterations);
    EXPECT_GT(force[0], 0.2 * edge);  // the defect: a fifth of a free face's force or more
    // Measured: 0.026 (2D), 0.19 (3D, whose zone here is smaller than a coarse horizon).
    EXPECT_LT(force[1], (dim == 2 ? 0.05 : 0.3) * force[0]);
    EXPECT_GE(solved.smallest, kSmallestFactor);
  }
}

/// Largest |T_p| over the particles in the box [x0, x1] × [y0, y1].
double largest_moment(const Simulation& sim, double x0, double x1, double y0, double y1) {
  const auto& p = sim.particles();
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.reference_position[0][i], y = p.reference_position[1][i];
    if (x < x0 || x > x1 || y < y0 || y > y1) continue;
    const auto t = third_moment(sim.bonds(), p, sim.setup().partial_volume, sim.micromodulus(), i);
    double n = 0.0;
    for (const double v : t) n += v * v;
    worst = std::max(worst, std::sqrt(n));
  }
  return worst;
}

TEST(InterfaceConsistency, EventsKeepTheInterfacesConsistentAndMomentumExact) {
  // Three events in a loaded, fracturing plate (a zone at the notch tip grows, a second appears
  // ahead of it), with re-sorts between them. The factors belong to the reference configuration
  // (broken bonds count like intact ones), so the moments T_p tell whether a homogeneous strain
  // would push on p; around the second zone no face or pre-crack is within reach of a
  // particle's bond partners' horizons.
  double moment[2] = {0, 0};
  for (const bool correction : {false, true}) {
    auto s = test::pulled_cracked_plate(1e-3);
    s.resort_fraction = 0.02;
    s.interface_correction = correction;
    Simulation sim(s);
    sim.run_steps(60);
    const Vec3 centres[3] = {{0.025, 0.01, 0}, {0.027, 0.01, 0}, {0.039, 0.0105, 0}};
    const double radii[3] = {3e-3, 5e-3, 2.5e-3};
    for (int e = 0; e < 3; ++e) {
      const auto ev = refine::split(sim, ball(sim, centres[e], radii[e]));
      if (correction)
        std::printf(
            "event %d: %zu parents, %zu constrained, %zu factors in [%.2f, %.2f] (%zu "
            "clipped), residual %.3f, %d iterations\n",
            e + 1, ev.parents, ev.interfaces.particles, ev.interfaces.bonds, ev.interfaces.smallest,
            ev.interfaces.largest, ev.interfaces.clipped, ev.interfaces.residual,
            ev.interfaces.iterations);
      EXPECT_EQ(ev.interfaces.bonds > 0, correction);
      EXPECT_GE(ev.interfaces.smallest, kSmallestFactor);
      EXPECT_LE(ev.interfaces.residual, 1.0);  // never worse than no correction
      sim.run_steps(20);
    }
    const auto e = sim.energies();
    double scale = 0.0;
    const auto& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      scale += p.density[i] * p.volume[i] * std::hypot(p.velocity[0][i], p.velocity[1][i]);
    EXPECT_LT(std::hypot(e.momentum[0], e.momentum[1]), 1e-12 * scale);  // opposite tractions
    moment[correction] = largest_moment(sim, 0.035, 0.043, 0.006, 0.013);
  }
  const double face = largest_moment(Simulation(test::pulled_cracked_plate(1e-3)), 0, 1, 0, 1);
  std::printf(
      "after 3 events: largest moment around the second zone %.3e (paper), %.3e "
      "(corrected); a free face's %.3e\n",
      moment[0], moment[1], face);
  EXPECT_GT(moment[0], 0.2 * face);
  EXPECT_LT(moment[1], 0.3 * moment[0]);  // measured 0.24: a small zone, partly corrected
}

}  // namespace
}  // namespace dhpd
