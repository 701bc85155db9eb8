// Bond rows (engine/discretization/bonds.*, bond_edit.cpp; docs/theory.md §2, §7, §18): a
// from-scratch build holds exactly the pairs brute force finds, each own bond with its length
// and weight and each dual side in the other row; the build is the same for 1 and 2 threads; on a
// uniform lattice with one horizon every entry holds both bonds of its pair; replacing own bonds
// keeps the rows consistent and equals a build of the new bond set; renumbering keeps every bond's
// length, state, factor and stiffness, ignores garbage and packs the rows.
#include <gtest/gtest.h>
#include <omp.h>

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
    const auto b = build_bond_rows(p, PartialVolume::Linear, {});
    const auto expected = brute_force_bonds(p);
    ASSERT_EQ(b.bond_count(), expected.size()) << dim;
    std::size_t dual_only = 0, dual_sides = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (auto k = b.begin(i); k < b.end(i); ++k) {
        const auto j = b.other[k];
        const auto own = expected.find({static_cast<std::int32_t>(i), j});
        const auto dual = expected.find({j, static_cast<std::int32_t>(i)});
        EXPECT_EQ(b.has_own(k), own != expected.end()) << dim << "D " << i << " -> " << j;
        EXPECT_EQ(b.has_dual(k), dual != expected.end()) << dim << "D " << j << " -> " << i;
        EXPECT_TRUE(b.own_intact(k) == b.has_own(k) && b.dual_intact(k) == b.has_dual(k));
        dual_sides += b.has_dual(k);
        dual_only += !b.has_own(k);
        if (own == expected.end()) continue;
        // 1/|ξ| is stored; |ξ| = 1/(1/|ξ|) is within an ulp of the distance, β at that length.
        EXPECT_NEAR(b.length(k), own->second.first, 2e-16 * own->second.first);
        EXPECT_NEAR(
            bond_weight(p, PartialVolume::Linear, i, static_cast<std::size_t>(j), b.length(k)),
            own->second.second, 1e-12);
      }
    EXPECT_EQ(dual_sides, expected.size()) << dim << "D: every bond's dual side in its row";
    EXPECT_GT(dual_only, 0u) << dim << "D: the cloud should have pairs in one horizon only";
    EXPECT_EQ(b.rows.garbage, 0);
    EXPECT_EQ(b.rows.arena, b.live);
    expect_consistent(b, p.size(), std::to_string(dim) + "D", false);
  }
}

TEST(Bonds, BuildIsTheSameForOneAndTwoThreads) {
  // Dual-only entries are placed by whichever thread reaches them, then every row is sorted.
  const auto p = test::random_cloud(3, 6000, 0.02, 3.0, 3.015, 17);
  for (const auto pv : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact}) {
    omp_set_num_threads(1);
    const auto one = build_bond_rows(p, pv, {});
    omp_set_num_threads(2);
    const auto two = build_bond_rows(p, pv, {});
    EXPECT_EQ(one.rows.start, two.rows.start);
    EXPECT_EQ(one.other, two.other);
    EXPECT_EQ(one.length_index, two.length_index);
    EXPECT_EQ(one.inverse_lengths, two.inverse_lengths);
    EXPECT_EQ(one.flags, two.flags);
    expect_consistent(two, p.size(), "two threads", false);
  }
}

TEST(Bonds, UniformLatticeWithOneHorizonHoldsBothBondsInEveryEntry) {
  for (const int dim : {1, 2, 3}) {
    Section s;
    s.dim = dim;
    const auto p = test::lattice_store(dim, dim == 1 ? 30 : (dim == 2 ? 14 : 7), 1e-3, 3.015, s);
    for (const auto pv : {PartialVolume::None, PartialVolume::Linear}) {
      const auto b = build_bond_rows(p, pv, {});
      expect_consistent(b, p.size(), std::to_string(dim) + "D", false);
      std::size_t one_sided = 0;
      for (std::size_t i = 0; i < p.size(); ++i)
        for (auto k = b.begin(i); k < b.end(i); ++k) one_sided += !(b.has_own(k) && b.has_dual(k));
      EXPECT_EQ(one_sided, 0u) << dim;
      EXPECT_EQ(b.live, b.own_bonds) << dim << ": one entry per directed bond";
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
      EXPECT_EQ(b.own_count(centre), interior) << dim;
    }
  }
}

/// (owner, neighbour) → intact of every own bond.
using BondSet = std::map<std::pair<std::int32_t, std::int32_t>, bool>;
BondSet own_bonds(const BondRows& b) {
  BondSet m;
  for (std::size_t i = 0; i < b.particles(); ++i)
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      m[{static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)}] = b.own_intact(k);
    });
  return m;
}

TEST(Bonds, ReplacingOwnBondsKeepsTheRowsConsistentAndHoldsExactlyTheNewBonds) {
  for (const int dim : {2, 3}) {
    const auto p = test::random_cloud(dim, 500, dim == 2 ? 0.02 : 0.07, 3.0, 3.015, 40 + dim);
    auto b = build_bond_rows(p, PartialVolume::Linear, {});
    auto expected = own_bonds(b);
    std::mt19937 rng(9 + dim);
    // Owners lose some bonds, keep others (some broken), and gain bonds to new neighbours (rows
    // grow past their room and move); one owner loses every bond.
    std::vector<std::int32_t> owners;
    for (std::int32_t i = 0; i < 500; i += 7) owners.push_back(i);
    std::vector<std::vector<NewBond>> bonds(owners.size());
    for (std::size_t r = 0; r < owners.size(); ++r) {
      const auto i = owners[r];
      for (auto it = expected.begin(); it != expected.end();)
        it = it->first.first == i ? expected.erase(it) : std::next(it);
      if (r == 3) continue;
      std::vector<std::int32_t> to;
      for (std::int32_t j = 0; j < 500; ++j)
        if (j != i && rng() % 4 == 0) to.push_back(j);
      for (const auto j : to) {
        const bool intact = rng() % 3 != 0;
        bonds[r].push_back({j, intact});
        expected[{i, j}] = intact;
      }
    }
    const auto changed = replace_own_bonds(b, p, owners, bonds);
    EXPECT_GT(b.rows.garbage, 0) << "rows should have moved";
    expect_consistent(b, p.size(), std::to_string(dim) + "D after the replacement", false);
    EXPECT_TRUE(own_bonds(b) == expected)
        << dim << "D: a bond missing, extra or in the wrong state";
    EXPECT_TRUE(std::is_sorted(changed.begin(), changed.end()));
    for (const auto i : owners) EXPECT_TRUE(std::binary_search(changed.begin(), changed.end(), i));
    // Lengths are those of the reference positions, as a build gives them.
    for (std::size_t i = 0; i < p.size(); ++i)
      for (auto k = b.begin(i); k < b.end(i); ++k)
        EXPECT_EQ(b.inverse_length(k),
                  inverse_reference_length(p, i, static_cast<std::size_t>(b.other[k])));
  }
}

TEST(Bonds, RenumberedRowsKeepEveryBondUnderARandomPermutation) {
  for (const int dim : {2, 3}) {
    const auto p = test::random_cloud(dim, 400, dim == 2 ? 0.02 : 0.07, 3.0, 3.015, 90 + dim);
    auto a = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear,
                            Material{72e9, 2440, 3.8}, Section{dim});
    auto& b = a.bonds;
    // State that must survive: some bonds broken (both sides), factors of level interfaces.
    std::mt19937 rng(4 + dim);
    test::break_some_and_scale(b, p.size(), rng);
    a.refresh(p);
    // Row 3 grows the way an event grows it: it moves to the end of the arena, leaving garbage.
    std::vector<NewBond> row3;
    for_each_own_bond(b, 3, [&](std::int64_t k, std::size_t j) {
      row3.push_back({static_cast<std::int32_t>(j), b.own_intact(k)});
    });
    for (std::int32_t j = 390; j < 400; ++j) row3.push_back({j, true});
    replace_own_bonds(b, p, {3}, {row3});
    a.refresh(p);
    ASSERT_GT(b.rows.garbage, 0);
    expect_consistent(b, p.size(), "before");

    std::vector<std::int32_t> order(p.size()), new_index(p.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    for (std::size_t k = 0; k < order.size(); ++k)
      new_index[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
    const auto renumbered = renumbered_rows(b, order, new_index);

    EXPECT_EQ(renumbered.own_bonds, b.own_bonds);
    EXPECT_EQ(renumbered.rows.garbage, 0);
    EXPECT_EQ(renumbered.rows.arena, renumbered.live);
    EXPECT_EQ(renumbered.rows.capacity, renumbered.rows.count);
    expect_consistent(renumbered, p.size(), "after");
    // Every entry with its length, flags, factor and stiffness under its new indices.
    using Entry = std::tuple<double, std::uint8_t, float, float>;
    std::map<std::pair<std::int32_t, std::int32_t>, Entry> before, after;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (auto k = b.begin(i); k < b.end(i); ++k)
        before[{new_index[i], new_index[static_cast<std::size_t>(b.other[k])]}] = {
            b.inverse_length(k), b.flags[k], b.factor[k], b.stiffness[k]};
    for (std::size_t i = 0; i < p.size(); ++i)
      for (auto k = renumbered.begin(i); k < renumbered.end(i); ++k)
        after[{static_cast<std::int32_t>(i), renumbered.other[k]}] = {
            renumbered.inverse_length(k), renumbered.flags[k], renumbered.factor[k],
            renumbered.stiffness[k]};
    EXPECT_TRUE(before == after) << dim << "D: an entry changed or went missing";

    // Capacity: exact without spare room; with it, a row an event moves fits without a copy of
    // the arrays; and arrays that must grow take half as much again, not twice the arena.
    const auto arena = static_cast<std::size_t>(renumbered.rows.arena);
    EXPECT_EQ(renumbered.other.capacity(), arena);
    auto roomy = renumbered_rows(b, order, new_index, 0.125);
    EXPECT_GE(roomy.other.capacity(), arena + arena / 8);
    // Row 3 (its new index) again, with one more bond: it outgrows its room and moves.
    const auto owner = new_index[3];
    std::vector<NewBond> grown;
    for (const auto& nb : row3)
      grown.push_back({new_index[static_cast<std::size_t>(nb.neighbor)], nb.intact});
    for (std::int32_t j = 0; grown.size() == row3.size(); ++j)
      if (j != owner && std::none_of(grown.begin(), grown.end(),
                                     [&](const NewBond& nb) { return nb.neighbor == j; }))
        grown.push_back({j, true});
    std::sort(grown.begin(), grown.end(),
              [](const NewBond& x, const NewBond& y) { return x.neighbor < y.neighbor; });
    const auto* storage = roomy.other.data();
    replace_own_bonds(roomy, p, {owner}, {grown});
    EXPECT_EQ(roomy.other.data(), storage) << "the move copied the arrays";
    auto tight = renumbered;
    replace_own_bonds(tight, p, {owner}, {grown});
    EXPECT_GT(tight.rows.arena, renumbered.rows.arena);
    EXPECT_LE(tight.other.capacity(), static_cast<std::size_t>(tight.rows.arena) * 3 / 2 + 1);
  }
}

}  // namespace
}  // namespace dhpd
