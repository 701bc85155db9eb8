// The force kernel with one entry per neighbour pair and the fused break test (docs/theory.md
// §4, §18): rows hold each neighbour once, the fused pass breaks exactly the bonds a brute-force
// stretch test breaks, the result equals an elastic pass over rows rebuilt from the new bond
// states, the damage it refreshes equals a full pass, and the plain and AVX2 builds give the same
// bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "engine/base/parallel.hpp"
#include "engine/physics/force_kernel.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

struct Stretched {
  ParticleStore p;
  test::Assembly a;
};

/// A cloud with horizons over a factor 4 and a random displacement large enough that a fraction
/// of the bonds passes the critical stretch s0 (set per particle, some owners no_fail).
Stretched stretched_cloud(int dim, std::uint64_t seed) {
  const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 500 : 600);
  const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.02 : 0.05);
  Stretched s{test::random_cloud(dim, n, h, 4.0, 3.015, seed), {}};
  Section sec;
  sec.dim = dim;
  s.a = test::assemble(s.p, ForceModel::DualHorizon, PartialVolume::Linear, {1e9, 1000, 1.0}, sec);
  s.a.s0.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.a.s0[i] = 0.02 + 0.01 * static_cast<double>(i % 7);
    s.p.no_fail[i] = i % 11 == 0;
    for (int d = 0; d < dim; ++d)
      test::set_displacement(s.p, d, i, 0.03 * h * std::sin(13.0 * i + d));
  }
  s.a.rows = build_interactions({ForceModel::DualHorizon, s.a.bonds, s.a.dual, s.p, s.a.C, s.a.s0});
  return s;
}

RowInputs inputs_of(const Stretched& s) {
  return {ForceModel::DualHorizon, s.a.bonds, s.a.dual, s.p, s.a.C, s.a.s0};
}

class ForceKernel : public ::testing::TestWithParam<int> {};

TEST_P(ForceKernel, RowsHoldEachNeighbourOnceInOrder) {
  const auto s = stretched_cloud(GetParam(), 3);
  const auto& il = s.a.rows;
  std::size_t both = 0;
  for (std::size_t i = 0; i < s.p.size(); ++i) {
    std::set<std::int32_t> expected;
    for (auto b = s.a.bonds.begin(i); b < s.a.bonds.end(i); ++b)
      expected.insert(s.a.bonds.neighbor[b]);
    for (auto d = s.a.dual.begin(i); d < s.a.dual.end(i); ++d)
      expected.insert(s.a.bonds.owner[s.a.dual.bond[d]]);
    ASSERT_EQ(static_cast<std::size_t>(il.end(i) - il.begin(i)), expected.size()) << i;
    auto it = expected.begin();
    for (auto k = il.begin(i); k < il.end(i); ++k, ++it) {
      EXPECT_EQ(il.other[k], *it);
      both += il.own_bond[k] >= 0 && il.dual_bond[k] >= 0;
    }
  }
  EXPECT_GT(both, 0u);
  EXPECT_LT(il.size(), s.a.bonds.size() + s.a.dual.bond.size());  // pairs merged
}

TEST_P(ForceKernel, FusedBreakingMatchesBruteForceAndARebuild) {
  auto s = stretched_cloud(GetParam(), 5);
  auto& bonds = s.a.bonds;
  std::vector<std::uint8_t> expected(bonds.slots(), 0);
  std::size_t expected_broken = 0;
  for (std::size_t i = 0; i < s.p.size(); ++i)
    for (auto b = bonds.begin(i); b < bonds.end(i); ++b) {
      const auto j = static_cast<std::size_t>(bonds.neighbor[b]);
      double l2 = 0;
      for (int d = 0; d < s.p.dim(); ++d) {
        const double x = s.p.position[d][j] - s.p.position[d][i];
        l2 += x * x;
      }
      const double stretch = std::sqrt(l2) / bonds.length[b] - 1.0;
      // Brute force in stretch form (not the squared-length form): a tie at s0 is improbable.
      const bool breaks = !s.p.no_fail[i] && stretch >= s.a.s0[i];
      expected[b] = breaks ? 0 : 1;
      expected_broken += breaks;
    }
  ASSERT_GT(expected_broken, 0u);
  ASSERT_LT(expected_broken, bonds.size() / 2);
  compute_damage(bonds, s.p);
  const auto broken = force_and_break(s.a.rows, bonds, s.p, inputs_of(s));
  EXPECT_EQ(static_cast<std::size_t>(broken), expected_broken);
  // The pass refreshed the damage of exactly the rows that broke: a full pass gives the same bits.
  auto full = s.p;
  compute_damage(bonds, full);
  EXPECT_EQ(0, std::memcmp(full.damage.data(), s.p.damage.data(), s.p.size() * sizeof(double)));
  EXPECT_GT(*std::max_element(s.p.damage.begin(), s.p.damage.end()), 0.0);
  for (std::size_t i = 0; i < s.p.size(); ++i)
    for (auto b = bonds.begin(i); b < bonds.end(i); ++b) ASSERT_EQ(bonds.intact[b], expected[b]);
  // Rows rebuilt from the new bond states give the same entries and the same force bits.
  auto fused_force = s.p.force_density;
  const auto rebuilt = build_interactions(inputs_of(s));
  internal_force_density(rebuilt, s.p);
  for (int d = 0; d < s.p.dim(); ++d)
    EXPECT_EQ(0, std::memcmp(fused_force[d].data(), s.p.force_density[d].data(),
                             s.p.size() * sizeof(double)));
  EXPECT_EQ(rebuilt.coefficient, s.a.rows.coefficient);
  EXPECT_EQ(rebuilt.alive, s.a.rows.alive);
  EXPECT_EQ(0, std::memcmp(rebuilt.break_at.data(), s.a.rows.break_at.data(),
                           rebuilt.break_at.size() * sizeof(float)));
  // A second pass on the same positions breaks nothing more.
  EXPECT_EQ(force_and_break(s.a.rows, bonds, s.p, inputs_of(s)), 0);
}

// The total strain energy from the rows' pair coefficients (each pair once per row, own and dual
// parts together) is the sum of V_i W_i over own bonds, with broken bonds and both force models.
TEST_P(ForceKernel, PairEnergyOfRowsEqualsOwnBondEnergy) {
  for (const auto model : {ForceModel::DualHorizon, ForceModel::ClassicalVariable}) {
    auto s = stretched_cloud(GetParam(), 7);
    s.a.rows = build_interactions({model, s.a.bonds, s.a.dual, s.p, s.a.C, s.a.s0});
    const RowInputs in{model, s.a.bonds, s.a.dual, s.p, s.a.C, s.a.s0};
    ASSERT_GT(force_and_break(s.a.rows, s.a.bonds, s.p, in), 0);
    std::vector<double> w;
    strain_energy_density(s.a.bonds, s.p, s.a.C, w);
    double expected = 0.0;
    for (std::size_t i = 0; i < s.p.size(); ++i) expected += s.p.volume[i] * w[i];
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(strain_energy_total(s.a.rows, s.p), expected, 1e-12 * expected)
        << (model == ForceModel::ClassicalVariable ? "classical" : "dual-horizon");
    // A model factor or a dual part counted twice would be off by tens of percent.
    s.a.rows.coefficient.assign(s.a.rows.coefficient.size(), 0.0);
    EXPECT_EQ(strain_energy_total(s.a.rows, s.p), 0.0);
  }
}

TEST_P(ForceKernel, PlainAndAvx2BuildsGiveTheSameBits) {
  if (!kernel::avx2_available()) GTEST_SKIP() << "this CPU has no AVX2";
  const int dim = GetParam();
  for (const bool fracture : {false, true}) {
    std::vector<double> force[2][3];
    std::vector<std::uint8_t> intact[2];
    std::int64_t broken[2] = {0, 0};
    for (const auto build : {kernel::Build::Plain, kernel::Build::Avx2}) {
      auto s = stretched_cloud(dim, 9);
      const auto in = inputs_of(s);
      const kernel::Fields x{
          {s.p.position[0].data(), s.p.position[1].data(), s.p.position[2].data()},
          {s.p.force_density[0].data(), s.p.force_density[1].data(), s.p.force_density[2].data()}};
      const kernel::RowArrays r(s.a.rows);
      const kernel::Breaking w{&s.a.rows, &in, s.a.bonds.intact.data()};
      const auto row = with_dim(dim, [&](auto d) {
        return fracture ? kernel::row_kernel<d(), true>(build)
                        : kernel::row_kernel<d(), false>(build);
      });
      const int b = build == kernel::Build::Avx2;
      for (std::size_t i = 0; i < s.p.size(); ++i)
        broken[b] += row(static_cast<std::int64_t>(i), x, r, w);
      for (int d = 0; d < 3; ++d) force[b][d] = s.p.force_density[d];
      intact[b] = s.a.bonds.intact;
    }
    for (int d = 0; d < dim; ++d)
      EXPECT_EQ(0, std::memcmp(force[0][d].data(), force[1][d].data(), force[0][d].size() * 8))
          << "axis " << d << (fracture ? " with fracture" : "");
    EXPECT_EQ(intact[0], intact[1]);
    EXPECT_EQ(broken[0], broken[1]);
    if (fracture) {
      EXPECT_GT(broken[0], 0);
    }
  }
}

TEST_P(ForceKernel, PlainAndAvx2RowEnergiesGiveTheSameBits) {
  if (!kernel::avx2_available()) GTEST_SKIP() << "this CPU has no AVX2";
  const int dim = GetParam();
  auto s = stretched_cloud(dim, 11);
  ASSERT_GT(force_and_break(s.a.rows, s.a.bonds, s.p, inputs_of(s)), 0);  // some c_k = 0
  const double* const y[3] = {s.p.position[0].data(), s.p.position[1].data(),
                              s.p.position[2].data()};
  const kernel::RowArrays r(s.a.rows);
  std::vector<double> energy[2];
  for (const auto build : {kernel::Build::Plain, kernel::Build::Avx2}) {
    const auto row = with_dim(dim, [&](auto d) { return kernel::row_energy_kernel<d()>(build); });
    for (std::size_t i = 0; i < s.p.size(); ++i)
      energy[build == kernel::Build::Avx2].push_back(row(static_cast<std::int64_t>(i), y, r));
  }
  EXPECT_EQ(0, std::memcmp(energy[0].data(), energy[1].data(), energy[0].size() * 8));
  EXPECT_GT(*std::max_element(energy[0].begin(), energy[0].end()), 0.0);
}

// The energy a breaking force pass computes on the way is, row by row, the bits of the energy
// kernel run after the pass (broken entries add nothing), with the same forces, in both builds.
TEST_P(ForceKernel, FusedRowEnergyEqualsTheEnergyAfterThePass) {
  const int dim = GetParam();
  std::vector<kernel::Build> builds{kernel::Build::Plain};
  if (kernel::avx2_available()) builds.push_back(kernel::Build::Avx2);
  for (const auto build : builds) {
    auto plain = stretched_cloud(dim, 13), fused = plain;
    ASSERT_GT(force_and_break(plain.a.rows, plain.a.bonds, plain.p, inputs_of(plain)), 0);
    const auto in = inputs_of(fused);
    std::vector<double> energy(fused.p.size(), -1.0);
    const kernel::Fields x{
        {fused.p.position[0].data(), fused.p.position[1].data(), fused.p.position[2].data()},
        {fused.p.force_density[0].data(), fused.p.force_density[1].data(),
         fused.p.force_density[2].data()},
        energy.data()};
    const kernel::RowArrays r(fused.a.rows);
    const kernel::Breaking w{&fused.a.rows, &in, fused.a.bonds.intact.data()};
    const auto row =
        with_dim(dim, [&](auto d) { return kernel::row_kernel<d(), true, true>(build); });
    for (std::size_t i = 0; i < fused.p.size(); ++i) row(static_cast<std::int64_t>(i), x, r, w);
    EXPECT_EQ(fused.a.bonds.intact, plain.a.bonds.intact);
    for (int d = 0; d < dim; ++d)
      EXPECT_EQ(0, std::memcmp(fused.p.force_density[d].data(), plain.p.force_density[d].data(),
                               plain.p.size() * 8));
    const auto after = with_dim(dim, [&](auto d) { return kernel::row_energy_kernel<d()>(build); });
    const double* const y[3] = {fused.p.position[0].data(), fused.p.position[1].data(),
                                fused.p.position[2].data()};
    for (std::size_t i = 0; i < fused.p.size(); ++i)
      ASSERT_EQ(energy[i], after(static_cast<std::int64_t>(i), y, r)) << i;
    EXPECT_GT(*std::max_element(energy.begin(), energy.end()), 0.0);
    // Through the bond loop: the total from the row sums is strain_energy_total's.
    std::vector<double> sums;
    auto again = stretched_cloud(dim, 13);
    force_and_break(again.a.rows, again.a.bonds, again.p, inputs_of(again), &sums);
    EXPECT_EQ(strain_energy_of_row_sums(sums, again.p), strain_energy_total(again.a.rows, again.p));
  }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, ForceKernel, ::testing::Values(1, 2, 3));

}  // namespace
}  // namespace dhpd
