// Bonds and dual lists (engine/discretization/bonds.*; docs/theory.md §2, §7): a from-scratch build
// holds exactly the pairs brute force finds, with their lengths and weights; every dual entry of j
// names a bond whose neighbour is j and every bond appears exactly once in its neighbour's dual
// row; on a uniform lattice with one horizon the bonds are symmetric; renumbering the particles
// keeps every bond's length, weight, stiffness and state, ignores garbage slots and packs the rows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/discretization/bonds.hpp"
#include "tests/support/bonds.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using test::expect_consistent;

/// Every pair (i, j) with 0 < |X_j − X_i| <= δ_i, by brute force: (length, weight) of the linear
/// rule with r_j = Δx_j / 2 (docs/theory.md §7).
std::map<std::pair<std::int32_t, std::int32_t>, std::pair<double, double>> brute_force_bonds(
    const ParticleStore& p) {
  std::map<std::pair<std::int32_t, std::int32_t>, std::pair<double, double>> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < p.size(); ++j) {
      double d2 = 0.0;
      for (int a = 0; a < p.dim(); ++a) {
        const double d = p.reference_position[a][j] - p.reference_position[a][i];
        d2 += d * d;
      }
      const double d = std::sqrt(d2), delta = p.horizon[i], r = 0.5 * p.spacing[j];
      if (i == j || d == 0.0 || d > delta) continue;
      const double beta = d <= delta - r ? 1.0 : (delta + r - d) / (2.0 * r);
      out[{static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)}] = {d, beta};
    }
  return out;
}

TEST(Bonds, BuildFindsExactlyTheBruteForcePairsWithTheirLengthsAndWeights) {
  for (const int dim : {1, 2, 3}) {
    const std::size_t n = dim == 1 ? 150 : (dim == 2 ? 400 : 500);
    const double h = dim == 1 ? 0.01 : (dim == 2 ? 0.03 : 0.08);
    // Spacings spread over [h, 3h]: horizons differ, so the bond sets are not symmetric.
    const auto p = test::random_cloud(dim, n, h, 3.0, 3.015, 31 + dim);
    const auto bonds = build_bonds(p, PartialVolume::Linear, {});
    const auto expected = brute_force_bonds(p);
    ASSERT_EQ(bonds.size(), expected.size()) << dim;
    std::size_t asymmetric = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (auto k = bonds.begin(i); k < bonds.end(i); ++k) {
        const auto j = bonds.neighbor[k];
        const auto it = expected.find({static_cast<std::int32_t>(i), j});
        ASSERT_NE(it, expected.end()) << dim << "D bond " << i << " -> " << j;
        EXPECT_EQ(bonds.length[k], it->second.first);  // the same arithmetic: the same bits
        EXPECT_EQ(bonds.weight[k], it->second.second);
        EXPECT_EQ(bonds.intact[k], 1);
        EXPECT_EQ(bonds.stiffness[k], 1.0);
        asymmetric += !expected.count({j, static_cast<std::int32_t>(i)});
      }
      EXPECT_TRUE(std::is_sorted(bonds.neighbor.begin() + bonds.begin(i),
                                 bonds.neighbor.begin() + bonds.end(i)));
    }
    EXPECT_GT(asymmetric, 0u) << dim << "D: the cloud should have pairs in one horizon only";
    EXPECT_EQ(bonds.rows.garbage, 0);
    EXPECT_EQ(bonds.rows.arena, bonds.live);
  }
}

TEST(Bonds, DualEntriesReferToBondsOnTheirParticleEachBondOnce) {
  for (const int dim : {1, 2, 3}) {
    const auto p =
        test::random_cloud(dim, dim == 3 ? 600 : 400, dim == 3 ? 0.07 : 0.02, 4.0, 3.015, 7 + dim);
    for (const auto pv : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact}) {
      const auto bonds = build_bonds(p, pv, {});
      const auto dual = build_dual(bonds);
      expect_consistent(bonds, dual, p.size(), std::to_string(dim) + "D");
      // From scratch, every dual row is sorted by bond id and the dual rows hold every bond.
      std::int64_t entries = 0;
      for (std::size_t j = 0; j < p.size(); ++j) {
        EXPECT_TRUE(
            std::is_sorted(dual.bond.begin() + dual.begin(j), dual.bond.begin() + dual.end(j)));
        entries += dual.end(j) - dual.begin(j);
      }
      EXPECT_EQ(entries, bonds.live);
    }
  }
}

TEST(Bonds, UniformLatticeWithOneHorizonIsSymmetric) {
  for (const int dim : {1, 2, 3}) {
    Section s;
    s.dim = dim;
    const auto p = test::lattice_store(dim, dim == 1 ? 30 : (dim == 2 ? 14 : 7), 1e-3, 3.015, s);
    for (const auto pv : {PartialVolume::None, PartialVolume::Linear}) {
      const auto bonds = build_bonds(p, pv, {});
      const auto dual = build_dual(bonds);
      expect_consistent(bonds, dual, p.size());
      // (i -> j) exists exactly when (j -> i) does, with the same length and weight bits.
      std::map<std::pair<std::int32_t, std::int32_t>, std::pair<double, double>> by_pair;
      for (std::size_t i = 0; i < p.size(); ++i)
        for (auto k = bonds.begin(i); k < bonds.end(i); ++k)
          by_pair[{static_cast<std::int32_t>(i), bonds.neighbor[k]}] = {bonds.length[k],
                                                                        bonds.weight[k]};
      std::size_t missing = 0, different = 0;
      for (const auto& [ij, value] : by_pair) {
        const auto it = by_pair.find({ij.second, ij.first});
        if (it == by_pair.end()) {
          ++missing;
          continue;
        }
        different += it->second != value;
      }
      EXPECT_EQ(missing, 0u) << dim;
      EXPECT_EQ(different, 0u) << dim;
      // So each particle's dual row is as long as its own row.
      for (std::size_t i = 0; i < p.size(); ++i)
        EXPECT_EQ(dual.end(i) - dual.begin(i), bonds.end(i) - bonds.begin(i)) << i;
      // An interior particle has every lattice offset within 3.015 Δx: 6 in 1D, 28 in 2D, 122 in
      // 3D (counted by hand: offsets (a, b, c) with a² + b² + c² <= 9).
      std::size_t centre = 0;
      double best = 1e300;
      for (std::size_t i = 0; i < p.size(); ++i) {
        double d2 = 0.0;
        for (int a = 0; a < dim; ++a) d2 += std::pow(p.reference_position[a][i] - 0.0035, 2);
        if (d2 < best) best = d2, centre = i;
      }
      const std::int64_t interior = dim == 1 ? 6 : (dim == 2 ? 28 : 122);
      EXPECT_EQ(bonds.end(centre) - bonds.begin(centre), interior) << dim;
    }
  }
}

TEST(Bonds, DualAddAndRemoveKeepTheOthersInOrder) {
  Section s;
  s.dim = 2;
  const auto p = test::lattice_store(2, 10, 1e-3, 3.015, s);
  const auto bonds = build_bonds(p, PartialVolume::Linear, {});
  auto dual = build_dual(bonds);
  const std::size_t j = 44;
  auto row = [&] {
    return std::vector<BondId>(dual.bond.begin() + dual.begin(j), dual.bond.begin() + dual.end(j));
  };
  const auto before = row();
  ASSERT_GT(before.size(), 5u);
  const auto start = dual.rows.start[j];
  dual.remove(j, before[2]);
  auto expected = before;
  expected.erase(expected.begin() + 2);
  EXPECT_EQ(row(), expected);
  // Back in: appended at the end of the row, which still fits in its room and stays.
  dual.add(j, before[2]);
  expected.push_back(before[2]);
  EXPECT_EQ(row(), expected);
  EXPECT_EQ(dual.rows.start[j], start);
  EXPECT_EQ(dual.rows.garbage, 0);
  expect_consistent(bonds, dual, p.size());
  // One more than its room: the row moves to the end of the arena with its entries.
  dual.add(j, 123456);
  expected.push_back(123456);
  EXPECT_EQ(row(), expected);
  EXPECT_NE(dual.rows.start[j], start);
  EXPECT_EQ(dual.rows.garbage, static_cast<std::int64_t>(before.size()));
  dual.remove(j, 123456);
  expected.pop_back();
  EXPECT_EQ(row(), expected);
  expect_consistent(bonds, dual, p.size(), "after the move");
  EXPECT_THROW(dual.remove(j, 123456), EngineError);
}

/// (owner, neighbour) → (length, weight, stiffness, intact) of every live bond.
using BondMap = std::map<std::pair<std::int32_t, std::int32_t>,
                         std::tuple<double, double, double, std::uint8_t>>;
BondMap bond_map(const BondList& b) {
  BondMap m;
  for (std::size_t i = 0; i < b.particles(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      m[{static_cast<std::int32_t>(i), b.neighbor[k]}] = {b.length[k], b.weight[k], b.stiffness[k],
                                                          b.intact[k]};
  return m;
}

TEST(Bonds, RenumberedBondsKeepEveryBondUnderARandomPermutation) {
  for (const int dim : {2, 3}) {
    const auto p = test::random_cloud(dim, 400, dim == 2 ? 0.02 : 0.07, 3.0, 3.015, 90 + dim);
    auto bonds = build_bonds(p, PartialVolume::Linear, {});
    // State that must survive: some bonds broken, stiffness factors of interfaces.
    std::mt19937 rng(4 + dim);
    for (std::size_t k = 0; k < bonds.slots(); ++k) {
      if (rng() % 5 == 0) bonds.intact[k] = 0;
      bonds.stiffness[k] = 1.0 + 0.01 * static_cast<double>(rng() % 50);
    }
    // Row 3 grows the way an event grows it: it moves to the end of the arena, leaving garbage.
    const auto old_start = bonds.begin(3);
    const auto count = bonds.rows.count[3];
    const auto at = bonds.rows.make_room(3, count + 5);
    bonds.fit_arena();
    for (std::int32_t k = 0; k < count; ++k) {
      const auto from = static_cast<std::size_t>(old_start + k),
                 to = static_cast<std::size_t>(at + k);
      bonds.owner[to] = bonds.owner[from], bonds.neighbor[to] = bonds.neighbor[from];
      bonds.length[to] = bonds.length[from], bonds.weight[to] = bonds.weight[from];
      bonds.stiffness[to] = bonds.stiffness[from], bonds.intact[to] = bonds.intact[from];
      bonds.owner[from] = bonds.neighbor[from] = -1;
    }
    ASSERT_GT(bonds.rows.garbage, 0);
    expect_consistent(bonds, build_dual(bonds), p.size(), "before");
    const auto before = bond_map(bonds);

    std::vector<std::int32_t> order(p.size()), new_index(p.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    for (std::size_t k = 0; k < order.size(); ++k)
      new_index[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
    const auto renumbered = renumbered_bonds(bonds, order, new_index);

    EXPECT_EQ(renumbered.size(), bonds.size());
    EXPECT_EQ(renumbered.rows.garbage, 0);
    EXPECT_EQ(renumbered.rows.arena, renumbered.live);
    EXPECT_EQ(renumbered.rows.capacity, renumbered.rows.count);
    expect_consistent(renumbered, build_dual(renumbered), p.size(), "after");
    BondMap expected;
    for (const auto& [ij, value] : before)
      expected[{new_index[static_cast<std::size_t>(ij.first)],
                new_index[static_cast<std::size_t>(ij.second)]}] = value;
    EXPECT_TRUE(bond_map(renumbered) == expected) << dim << "D: a bond changed or went missing";
    for (std::size_t k = 0; k < p.size(); ++k) {
      EXPECT_EQ(renumbered.rows.count[k], bonds.rows.count[static_cast<std::size_t>(order[k])]);
      EXPECT_TRUE(std::is_sorted(renumbered.neighbor.begin() + renumbered.begin(k),
                                 renumbered.neighbor.begin() + renumbered.end(k)));
    }
    // The identity permutation gives back a packed copy of the same bonds.
    std::iota(order.begin(), order.end(), 0);
    EXPECT_TRUE(bond_map(renumbered_bonds(bonds, order, order)) == before);
  }
}

}  // namespace
}  // namespace dhpd
