// Pre-cracks in the bonds (docs/theory.md §8): no bond crosses a crack; a plate pulled apart opens
// only along it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "geometry/crack.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using geometry::Crack;

/// Every pair within the horizon becomes a bond exactly when its segment crosses no crack.
TEST(CrackBonds, BondsAreExactlyThePairsThatCrossNoCrack) {
  for (int dim : {2, 3}) {
    Section s;
    s.dim = dim;
    auto p = test::lattice_store(dim, dim == 2 ? 20 : 8, 1e-3, 3.015, s);
    std::vector<Crack> cracks;
    if (dim == 2)
      cracks.push_back({{{0, 0.0101, 0}, {0.012, 0.0101, 0}}});
    else
      cracks.push_back(
          {{{0, 0, 0.0041}, {0.005, 0, 0.0041}, {0.005, 0.008, 0.0041}, {0, 0.008, 0.0041}}});
    const auto bonds = build_bond_rows(p, PartialVolume::None, cracks);
    std::size_t expected = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t j = 0; j < p.size(); ++j) {
        if (i == j) continue;
        const geometry::Vec3 a{p.reference_position[0][i], p.reference_position[1][i],
                               p.reference_position[2][i]};
        const geometry::Vec3 b{p.reference_position[0][j], p.reference_position[1][j],
                               p.reference_position[2][j]};
        if (geometry::norm(b - a) <= p.horizon[i] && !geometry::crosses(cracks[0], a, b, dim))
          ++expected;
      }
    std::size_t crossing = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (auto k = bonds.begin(i); k < bonds.end(i); ++k) {
        const auto j = static_cast<std::size_t>(bonds.other[k]);
        const geometry::Vec3 a{p.reference_position[0][i], p.reference_position[1][i],
                               p.reference_position[2][i]};
        const geometry::Vec3 b{p.reference_position[0][j], p.reference_position[1][j],
                               p.reference_position[2][j]};
        crossing += geometry::crosses(cracks[0], a, b, dim);
      }
    EXPECT_EQ(crossing, 0u) << dim;
    EXPECT_EQ(bonds.bond_count(), expected) << dim;
    EXPECT_LT(bonds.bond_count(), build_bond_rows(p, PartialVolume::None, {}).bond_count()) << dim;
  }
}

TEST(CrackBonds, PlatePulledApartOpensOnlyAlongTheCrack) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.materials = {{72e9, 2440, 0}};
  using geometry::Box;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.04, 0.02, 0}}, 5e-4, 0}}, 2);
  s.cracks = {{{{0.0, 0.01, 0}, {0.02, 0.01, 0}}}};
  BoundaryCondition top, bottom;
  top.kind = bottom.kind = BoundaryCondition::Kind::Velocity;
  top.region = Box{{0, 0.0195, 0}, {0.04, 0.02, 0}};
  bottom.region = Box{{0, 0, 0}, {0.04, 0.0005, 0}};
  top.velocity[1] = 0.5;
  bottom.velocity[1] = -0.5;
  s.boundary_conditions = {top, bottom};
  Simulation sim(s);
  sim.run_steps(1500);
  const auto& p = sim.particles();
  // Opening = u_y just above the crack line minus just below it, at x near 5 mm and 35 mm.
  auto opening = [&](double x) {
    double above = 0, below = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (std::abs(p.reference_position[0][i] - x) > 2.6e-4) continue;
      if (std::abs(p.reference_position[1][i] - 0.01025) < 1e-6) above = p.displacement[1][i];
      if (std::abs(p.reference_position[1][i] - 0.00975) < 1e-6) below = p.displacement[1][i];
    }
    return above - below;
  };
  const double cracked = opening(0.00525), intact = opening(0.03525);
  std::printf("after %.3g us: opening across the crack %.3e m, across intact material %.3e m\n",
              sim.time() * 1e6, cracked, intact);
  EXPECT_GT(cracked, 0.0);
  EXPECT_GT(cracked, 20.0 * std::abs(intact));
}

}  // namespace
}  // namespace dhpd
