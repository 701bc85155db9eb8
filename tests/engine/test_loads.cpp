// Loads (engine/physics/loads.*; docs/theory.md §11): a traction t on a layer becomes the body
// force t × (face measure) / (layer volume) = t / (layer depth) on every particle of the layer, so
// the total force is t × the loaded face's area in 1D, 2D and 3D, on one lattice or two; velocity
// and fixed conditions prescribe exactly their components; a region that selects nothing is
// refused by its index; after an edit, a successor takes over its predecessor's entries and a
// self-successor keeps them; renumbering moves every entry with its particle.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/physics/loads.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using geometry::Box;

Section section_of(int dim) {
  Section s;
  s.dim = dim;
  s.thickness = 2e-3;
  s.area = 3e-4;
  return s;
}

BoundaryCondition traction(const Box& region, const Vec3& t, int normal_axis) {
  BoundaryCondition bc;
  bc.kind = BoundaryCondition::Kind::Traction;
  bc.region = region;
  bc.traction = t;
  bc.normal_axis = normal_axis;
  return bc;
}

/// Σ b_i V_i over the particles loaded by condition entries.
Vec3 total_force(const ResolvedLoads& r, const ParticleStore& p) {
  Vec3 f{0, 0, 0};
  for (std::size_t k = 0; k < r.loaded.size(); ++k)
    for (int a = 0; a < 3; ++a)
      f[a] += r.body_force[k][a] * p.volume[static_cast<std::size_t>(r.loaded[k])];
  return f;
}

TEST(Loads, TractionTotalForceIsTractionTimesTheLoadedArea) {
  const double dx = 1e-3;
  for (const int dim : {1, 2, 3}) {
    const Section s = section_of(dim);
    const int cells = dim == 3 ? 6 : 20;
    const double side = cells * dx;
    const auto p = test::lattice_store(dim, cells, dx, 3.015, s);
    // The top two layers along the last axis (x in 1D), pulled along that axis and sheared.
    const int axis = dim - 1;
    Box layer;
    for (int a = 0; a < dim; ++a) layer.max[a] = side;
    layer.min[axis] = side - 2 * dx;
    const Vec3 t{dim > 1 ? 3e6 : 5e6, dim > 1 ? 5e6 : 0.0, dim > 2 ? -2e6 : 0.0};
    const auto r = resolve_loads({traction(layer, t, axis)}, p);
    // The loaded face: A in 1D, side × thickness in 2D, side² in 3D.
    const double face = dim == 1 ? s.area : (dim == 2 ? side * s.thickness : side * side);
    const double depth = 2 * dx;  // two layers of cells: from side − 2Δx to side
    const std::size_t expected_particles = dim == 1 ? 2 : (dim == 2 ? 2 * 20 : 2 * 36);
    ASSERT_EQ(r.loaded.size(), expected_particles) << dim;
    ASSERT_EQ(r.condition_body_force.size(), 1u);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(r.condition_body_force[0][a], t[a] / depth, 1e-12 * std::abs(t[0]) / depth);
    for (const auto& b : r.body_force) EXPECT_EQ(b, r.condition_body_force[0]);
    const auto f = total_force(r, p);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(f[a], t[a] * face, 1e-12 * std::abs(t[0]) * face) << dim << "D axis " << a;
    EXPECT_TRUE(r.prescribed.empty());
  }
}

TEST(Loads, TractionOnALayerOfTwoSpacingsStillGivesTractionTimesArea) {
  // A 2D plate whose right part is twice as fine: the loaded top layer crosses the jump. The depth
  // is the layer's extent (its coarse cells reach deepest), and the fine cells hold the volume of
  // the coarse cells they replace.
  const Section s = section_of(2);
  const std::vector<geometry::LatticePart> parts = {{Box{{0, 0, 0}, {0.02, 0.01, 0}}, 1e-3, 0},
                                                    {Box{{0.01, 0, 0}, {0.02, 0.01, 0}}, 5e-4, 0}};
  const auto p = test::store_from_points(geometry::fill_lattice(parts, 2), 2, 3.015, s);
  const Vec3 t{0, 4e6, 0};
  const auto r = resolve_loads({traction(Box{{0, 0.009, 0}, {0.02, 0.01, 0}}, t, 1)}, p);
  // Coarse cells of the top row span [9, 10] mm, fine ones [9, 9.5] and [9.5, 10]: depth 1 mm.
  EXPECT_NEAR(r.condition_body_force[0][1], 4e6 / 1e-3, 1e-3);
  EXPECT_EQ(r.loaded.size(), 10u + 2u * 20u);
  EXPECT_NEAR(total_force(r, p)[1], 4e6 * 0.02 * s.thickness, 1e-9);
}

TEST(Loads, VelocityAndFixedConditionsPrescribeExactlyTheirComponents) {
  const Section s = section_of(2);
  const auto p = test::lattice_store(2, 10, 1e-3, 3.015, s);
  BoundaryCondition fixed;  // the left column, every in-plane component held at zero
  fixed.kind = BoundaryCondition::Kind::Fixed;
  fixed.region = Box{{0, 0, 0}, {1e-3, 0.01, 0}};
  BoundaryCondition pull;  // the right column: v_y = 2 only, v_x left free
  pull.kind = BoundaryCondition::Kind::Velocity;
  pull.region = Box{{0.009, 0, 0}, {0.01, 0.01, 0}};
  pull.velocity[1] = 2.0;
  BoundaryCondition corner;  // the top right particle again: v_x = −1
  corner.kind = BoundaryCondition::Kind::Velocity;
  corner.region = Box{{0.009, 0.009, 0}, {0.01, 0.01, 0}};
  corner.velocity[0] = -1.0;
  const auto r = resolve_loads({fixed, pull, corner}, p);
  ASSERT_EQ(r.prescribed.size(), 10u + 10u + 1u);
  ASSERT_EQ(r.mask.size(), r.prescribed.size());
  ASSERT_EQ(r.prescribed_velocity.size(), r.prescribed.size());
  EXPECT_TRUE(r.loaded.empty());
  EXPECT_EQ(r.condition_body_force, (std::vector<Vec3>(3, Vec3{0, 0, 0})));
  for (std::size_t k = 0; k < r.prescribed.size(); ++k) {
    const auto i = static_cast<std::size_t>(r.prescribed[k]);
    const double x = p.reference_position[0][i], y = p.reference_position[1][i];
    using Mask = std::array<std::uint8_t, 3>;
    if (k < 10) {  // in the order of the conditions, each condition's particles ascending
      EXPECT_LT(x, 1e-3);
      EXPECT_EQ(r.mask[k], (Mask{1, 1, 0}));  // z is not a component in 2D
      EXPECT_EQ(r.prescribed_velocity[k], (Vec3{0, 0, 0}));
    } else if (k < 20) {
      EXPECT_GT(x, 0.009);
      EXPECT_EQ(r.mask[k], (Mask{0, 1, 0}));
      EXPECT_EQ(r.prescribed_velocity[k], (Vec3{0, 2.0, 0}));
    } else {
      EXPECT_GT(x, 0.009);
      EXPECT_GT(y, 0.009);
      EXPECT_EQ(r.mask[k], (Mask{1, 0, 0}));
      EXPECT_EQ(r.prescribed_velocity[k], (Vec3{-1.0, 0, 0}));
    }
    if (k > 0 && k != 10 && k != 20) {
      EXPECT_LT(r.prescribed[k - 1], r.prescribed[k]);
    }
  }
  // In 3D, fixed holds all three components; in 1D only x.
  for (const int dim : {1, 3}) {
    const auto q = test::lattice_store(dim, 4, 1e-3, 3.015, section_of(dim));
    fixed.region = Box{{0, 0, 0}, {1e-3, 0.004, 0.004}};
    const auto held = resolve_loads({fixed}, q);
    ASSERT_FALSE(held.mask.empty());
    for (const auto& m : held.mask)
      EXPECT_EQ(m, (dim == 3 ? std::array<std::uint8_t, 3>{1, 1, 1}
                             : std::array<std::uint8_t, 3>{1, 0, 0}));
  }
}

TEST(Loads, ARegionThatSelectsNothingIsRefusedByItsIndex) {
  const auto p = test::lattice_store(2, 10, 1e-3, 3.015, section_of(2));
  BoundaryCondition inside, outside;
  inside.region = Box{{0, 0, 0}, {0.01, 1e-3, 0}};
  outside.region = Box{{0.5, 0.5, 0}, {0.6, 0.6, 0}};
  try {
    resolve_loads({inside, outside}, p);
    ADD_FAILURE() << "accepted a region outside the body";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "boundary_conditions.1.region: selects no particle (the region lies outside the "
              "body)");
  }
  // select() is plain containment of the reference positions.
  const auto chosen = select(p, inside.region);
  std::vector<std::int32_t> expected;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.reference_position[1][i] <= 1e-3) expected.push_back(static_cast<std::int32_t>(i));
  EXPECT_EQ(chosen, expected);
}

/// (particle, body force) of every loaded entry and (particle, mask, velocity) of every
/// prescribed one, as sorted multisets.
using Loaded = std::vector<std::tuple<std::int32_t, double, double, double>>;
using Held = std::vector<std::tuple<std::int32_t, std::array<std::uint8_t, 3>, double, double>>;
Loaded loaded_of(const ResolvedLoads& r) {
  Loaded out;
  for (std::size_t k = 0; k < r.loaded.size(); ++k)
    out.emplace_back(r.loaded[k], r.body_force[k][0], r.body_force[k][1], r.body_force[k][2]);
  std::sort(out.begin(), out.end());
  return out;
}
Held held_of(const ResolvedLoads& r) {
  Held out;
  for (std::size_t k = 0; k < r.prescribed.size(); ++k)
    out.emplace_back(r.prescribed[k], r.mask[k], r.prescribed_velocity[k][0],
                     r.prescribed_velocity[k][1]);
  std::sort(out.begin(), out.end());
  return out;
}

/// The particle at (x, y) of a 2D store.
std::int32_t index_at(const ParticleStore& p, double x, double y) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.reference_position[0][i] - x) < 1e-9 &&
        std::abs(p.reference_position[1][i] - y) < 1e-9)
      return static_cast<std::int32_t>(i);
  ADD_FAILURE() << "no particle at " << x << ", " << y;
  return 0;
}

TEST(Loads, SuccessorsTakeOverTheirPredecessorsEntriesAndSelfSuccessorsKeepTheirs) {
  const auto p = test::lattice_store(2, 10, 1e-3, 3.015, section_of(2));
  BoundaryCondition pull;
  pull.kind = BoundaryCondition::Kind::Velocity;
  pull.region = Box{{0.009, 0, 0}, {0.01, 0.01, 0}};
  pull.velocity[1] = 2.0;
  const std::vector<BoundaryCondition> bcs = {
      traction(Box{{0, 0.009, 0}, {0.01, 0.01, 0}}, Vec3{0, 1e6, 0}, 1), pull};
  auto r = resolve_loads(bcs, p);
  const auto loaded_before = loaded_of(r);
  const auto held_before = held_of(r);
  // A split of four parents as an event does it: each parent's slot holds its first child (a
  // self-successor), three more children get new slots from 100 on. The top right particle is
  // loaded and held, one of the top row only loaded, one of the right column only held, an
  // interior one carries nothing.
  const std::vector<std::int32_t> parents = {
      index_at(p, 9.5e-3, 9.5e-3), index_at(p, 5.5e-3, 9.5e-3), index_at(p, 9.5e-3, 1.5e-3),
      index_at(p, 4.5e-3, 4.5e-3)};
  std::vector<std::int32_t> successor, predecessor;
  std::int32_t next = 100;
  for (const auto q : parents) {
    successor.push_back(q), predecessor.push_back(q);
    for (int c = 0; c < 3; ++c) successor.push_back(next++), predecessor.push_back(q);
  }
  inherit_loads(r, successor, predecessor);
  // Expected by hand: every old entry once (self-successors add nothing), plus a copy of the
  // parent's entries for each new child.
  auto loaded_expected = loaded_before;
  auto held_expected = held_before;
  for (std::size_t k = 0; k < successor.size(); ++k) {
    if (successor[k] == predecessor[k]) continue;
    for (const auto& e : loaded_before)
      if (std::get<0>(e) == predecessor[k])
        loaded_expected.emplace_back(successor[k], std::get<1>(e), std::get<2>(e), std::get<3>(e));
    for (const auto& e : held_before)
      if (std::get<0>(e) == predecessor[k])
        held_expected.emplace_back(successor[k], std::get<1>(e), std::get<2>(e), std::get<3>(e));
  }
  std::sort(loaded_expected.begin(), loaded_expected.end());
  std::sort(held_expected.begin(), held_expected.end());
  EXPECT_EQ(loaded_of(r), loaded_expected);
  EXPECT_EQ(held_of(r), held_expected);
  EXPECT_EQ(loaded_of(r).size(), loaded_before.size() + 3 + 3);  // the top row's two parents
  EXPECT_EQ(held_of(r).size(), held_before.size() + 3 + 3);      // the right column's two
  EXPECT_EQ(r.body_force.size(), r.loaded.size());
  EXPECT_EQ(r.mask.size(), r.prescribed.size());
  // The traction's body force per particle is unchanged (it is N/m³): with the children's volumes
  // a quarter of their parent's, the total force is conserved by the split.
  for (const auto& b : r.body_force) EXPECT_EQ(b, r.condition_body_force[0]);
  // Nothing to inherit: a no-op.
  const auto again = r;
  inherit_loads(r, {7, 8}, {7, 8});
  EXPECT_EQ(loaded_of(r), loaded_of(again));
  EXPECT_EQ(held_of(r), held_of(again));
}

TEST(Loads, RenumberingMovesEveryEntryWithItsParticle) {
  const auto p = test::lattice_store(2, 10, 1e-3, 3.015, section_of(2));
  BoundaryCondition fixed;
  fixed.kind = BoundaryCondition::Kind::Fixed;
  fixed.region = Box{{0, 0, 0}, {1e-3, 0.01, 0}};
  auto r = resolve_loads(
      {traction(Box{{0, 0.009, 0}, {0.01, 0.01, 0}}, Vec3{2e6, 1e6, 0}, 1), fixed}, p);
  const auto before = r;
  std::vector<std::int32_t> new_index(p.size());
  std::iota(new_index.begin(), new_index.end(), 0);
  std::shuffle(new_index.begin(), new_index.end(), std::mt19937(3));
  renumber_loads(r, new_index);
  ASSERT_EQ(r.loaded.size(), before.loaded.size());
  ASSERT_EQ(r.prescribed.size(), before.prescribed.size());
  for (std::size_t k = 0; k < r.loaded.size(); ++k) {
    EXPECT_EQ(r.loaded[k], new_index[static_cast<std::size_t>(before.loaded[k])]);
    EXPECT_EQ(r.body_force[k], before.body_force[k]);
  }
  for (std::size_t k = 0; k < r.prescribed.size(); ++k) {
    EXPECT_EQ(r.prescribed[k], new_index[static_cast<std::size_t>(before.prescribed[k])]);
    EXPECT_EQ(r.mask[k], before.mask[k]);
    EXPECT_EQ(r.prescribed_velocity[k], before.prescribed_velocity[k]);
  }
}

}  // namespace
}  // namespace dhpd
