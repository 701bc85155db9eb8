// The force kernel with one entry per neighbour pair and the fused break test (docs/theory.md
// §4, §18): each entry's stored stiffness is its pair's intact bonds, once, with the same bits in
// both rows; the fused pass breaks exactly the bonds a brute-force stretch test breaks, on both
// rows of each bond, and the result equals an elastic pass over rows derived again from the new
// bond states; the damage it refreshes equals a full pass; and the plain and AVX2 builds give the
// same bits.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"
#include "engine/physics/force_kernel.hpp"
#include "tests/support/bonds.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

struct Stretched {
  ParticleStore p;
  test::Assembly a;
  BondConstants constants() const { return a.constants(p); }
};

/// A cloud with horizons over a factor 4 and a random displacement large enough that a fraction
/// of the bonds passes the critical stretch s0 (set per particle, some owners no_fail).
Stretched stretched_cloud(int dim, std::uint64_t seed, ForceModel model = ForceModel::DualHorizon) {
  const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 500 : 600);
  const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.02 : 0.05);
  Stretched s{test::random_cloud(dim, n, h, 4.0, 3.015, seed), {}};
  Section sec;
  sec.dim = dim;
  s.a = test::assemble(s.p, model, PartialVolume::Linear, {1e9, 1000, 1.0}, sec);
  s.a.s0.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.a.s0[i] = 0.02 + 0.01 * static_cast<double>(i % 7);
    s.p.no_fail[i] = i % 11 == 0;
    for (int d = 0; d < dim; ++d)
      test::set_displacement(s.p, d, i, 0.03 * h * std::sin(13.0 * i + d));
  }
  s.a.refresh(s.p);
  return s;
}

/// Every row of `s` through the kernel of `build`, in index order; the own bonds broken.
std::int64_t every_row(Stretched& s, int dim, kernel::Build build, bool fracture,
                       const kernel::StretchWatch& watch = {}) {
  const auto in = s.constants();
  std::vector<double> points;
  kernel::pack_points(s.p, points);
  const kernel::Fields x{
      {s.p.position[0].data(), s.p.position[1].data(), s.p.position[2].data()},
      {s.p.force_density[0].data(), s.p.force_density[1].data(), s.p.force_density[2].data()},
      nullptr,
      points.data()};
  const kernel::RowArrays r(s.a.bonds, s.p);
  const kernel::Breaking w{&s.a.bonds, &in, watch};
  const auto row = with_dim(dim, [&](auto d) {
    return fracture ? kernel::row_kernel<d(), true>(build) : kernel::row_kernel<d(), false>(build);
  });
  std::int64_t broken = 0;
  for (std::size_t i = 0; i < s.p.size(); ++i) broken += row(static_cast<std::int64_t>(i), x, r, w);
  return broken;
}

class ForceKernel : public ::testing::TestWithParam<int> {};

TEST(ForceKernelSideTask, RunsOnceAndLeavesThePassAsItWas) {
  // More than kParallelMinParticles particles, so the pass runs on a team of threads.
  const std::size_t n = 5000;
  const double h = 0.015;
  Stretched s{test::random_cloud(2, n, h, 2.0, 3.015, 77), {}};
  Section sec;
  sec.dim = 2;
  s.a = test::assemble(s.p, ForceModel::DualHorizon, PartialVolume::Linear, {1e9, 1000, 1.0}, sec);
  s.a.s0.assign(n, 0.02);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 2; ++d) test::set_displacement(s.p, d, i, 0.04 * h * std::sin(7.0 * i + d));
  s.a.refresh(s.p);
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    auto plain = s, shared = s;
    std::atomic<int> runs{0};
    const SideTask side = [&runs] { ++runs; };
    const auto broken = force_and_break(plain.a.bonds, plain.p, plain.constants());
    ASSERT_GT(broken, 0);
    EXPECT_EQ(
        force_and_break(shared.a.bonds, shared.p, shared.constants(), nullptr, nullptr, &side),
        broken);
    EXPECT_EQ(runs.load(), 1) << threads << " threads";
    EXPECT_EQ(plain.a.bonds.flags, shared.a.bonds.flags);
    for (int d = 0; d < 2; ++d)
      EXPECT_EQ(0, std::memcmp(plain.p.force_density[d].data(), shared.p.force_density[d].data(),
                               n * sizeof(double)));
    internal_force_density(shared.a.bonds, shared.p, nullptr, nullptr, nullptr, &side);
    const std::vector<std::int32_t> some = {3, 99, 4000};
    internal_force_density(shared.a.bonds, shared.p, &some, nullptr, nullptr, &side);
    EXPECT_EQ(runs.load(), 3) << "once per pass, on a subset of rows too";
  }
}

TEST_P(ForceKernel, StiffnessIsThePairsBondsOnceWithTheSameBitsInBothRows) {
  for (const auto model : {ForceModel::DualHorizon, ForceModel::ClassicalVariable}) {
    const auto s = stretched_cloud(GetParam(), 3, model);
    const auto& b = s.a.bonds;
    const bool dh = model == ForceModel::DualHorizon;
    test::expect_consistent(b, s.p.size(), "", dh);
    std::size_t both = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < s.p.size(); ++i)
      for (auto k = b.begin(i); k < b.end(i); ++k) {
        const auto j = static_cast<std::size_t>(b.other[k]);
        const double L = b.length(k);
        const double own = b.has_own(k) ? s.a.C[i] * bond_weight(s.p, s.a.rule, i, j, L) : 0.0;
        const double dual = b.has_dual(k) ? s.a.C[j] * bond_weight(s.p, s.a.rule, j, i, L) : 0.0;
        const double expected = dh ? own + dual : 2.0 * own;  // classical: 2C, no reaction
        const double stored = static_cast<double>(b.stiffness[k]) * b.stiffness_scale;
        both += b.has_own(k) && b.has_dual(k);
        if (expected == 0.0) {
          EXPECT_EQ(stored, 0.0);
          continue;
        }
        worst = std::max(worst, std::abs(stored / expected - 1.0));
      }
    EXPECT_GT(both, 0u);
    // Single precision: within 2⁻²⁴ of the double value (a dual part counted twice, or missing,
    // is off by tens of percent).
    EXPECT_LE(worst, 6e-8);
  }
}

TEST_P(ForceKernel, FusedBreakingMatchesBruteForceAndARebuild) {
  auto s = stretched_cloud(GetParam(), 5);
  auto& b = s.a.bonds;
  std::vector<std::uint8_t> expected(b.other.size(), 0);
  std::size_t expected_broken = 0;
  for (std::size_t i = 0; i < s.p.size(); ++i)
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      double l2 = 0;
      for (int d = 0; d < s.p.dim(); ++d) {
        const double x = s.p.position[d][j] - s.p.position[d][i];
        l2 += x * x;
      }
      const double stretch = std::sqrt(l2) / b.length(k) - 1.0;
      // Brute force in stretch form (not the squared-ratio form): a tie at s0 is improbable.
      const bool breaks = !s.p.no_fail[i] && stretch >= s.a.s0[i];
      expected[static_cast<std::size_t>(k)] = breaks ? 0 : 1;
      expected_broken += breaks;
    });
  ASSERT_GT(expected_broken, 0u);
  ASSERT_LT(expected_broken, b.bond_count() / 2);
  compute_damage(b, s.p, s.a.rule);
  const auto broken = force_and_break(b, s.p, s.constants());
  EXPECT_EQ(static_cast<std::size_t>(broken), expected_broken);
  // Both rows of every bond agree on its state, and the stiffness followed.
  test::expect_consistent(b, s.p.size(), "after the pass");
  // The pass refreshed the damage of exactly the rows that broke: a full pass gives the same bits.
  auto full = s.p;
  compute_damage(b, full, s.a.rule);
  EXPECT_EQ(0, std::memcmp(full.damage.data(), s.p.damage.data(), s.p.size() * sizeof(double)));
  EXPECT_GT(*std::max_element(s.p.damage.begin(), s.p.damage.end()), 0.0);
  for (std::size_t i = 0; i < s.p.size(); ++i)
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t) {
      ASSERT_EQ(b.own_intact(k), expected[static_cast<std::size_t>(k)] == 1);
    });
  // Stiffness derived again from the new bond states: the same bits and the same forces.
  auto fused_force = s.p.force_density;
  const auto stiffness = b.stiffness;
  const auto thresholds = b.break_ratio2;
  s.a.refresh(s.p);
  EXPECT_EQ(0, std::memcmp(stiffness.data(), b.stiffness.data(), stiffness.size() * 4));
  EXPECT_EQ(thresholds, b.break_ratio2);
  internal_force_density(b, s.p);
  for (int d = 0; d < s.p.dim(); ++d)
    EXPECT_EQ(0, std::memcmp(fused_force[d].data(), s.p.force_density[d].data(),
                             s.p.size() * sizeof(double)));
  // A second pass on the same positions breaks nothing more.
  EXPECT_EQ(force_and_break(b, s.p, s.constants()), 0);
}

// The total strain energy from the rows' pair stiffness (each pair once per row, own and dual
// parts together) is the sum of V_i W_i over own bonds, with broken bonds and both force models,
// to the single-precision rounding of the stored stiffness.
TEST_P(ForceKernel, PairEnergyOfRowsEqualsOwnBondEnergy) {
  for (const auto model : {ForceModel::DualHorizon, ForceModel::ClassicalVariable}) {
    auto s = stretched_cloud(GetParam(), 7, model);
    ASSERT_GT(force_and_break(s.a.bonds, s.p, s.constants()), 0);
    std::vector<double> w;
    strain_energy_density(s.a.bonds, s.constants(), w);
    double expected = 0.0;
    for (std::size_t i = 0; i < s.p.size(); ++i) expected += s.p.volume[i] * w[i];
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(strain_energy_total(s.a.bonds, s.p), expected, 1e-7 * expected)
        << (model == ForceModel::ClassicalVariable ? "classical" : "dual-horizon");
    // A model factor or a dual part counted twice would be off by tens of percent.
    s.a.bonds.stiffness.assign(s.a.bonds.stiffness.size(), 0.0f);
    EXPECT_EQ(strain_energy_total(s.a.bonds, s.p), 0.0);
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
      const int b = build == kernel::Build::Avx2;
      broken[b] = every_row(s, dim, build, fracture);
      for (int d = 0; d < 3; ++d) force[b][d] = s.p.force_density[d];
      intact[b] = s.a.bonds.flags;
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
  ASSERT_GT(force_and_break(s.a.bonds, s.p, s.constants()), 0);  // some c_k = 0
  const double* const y[3] = {s.p.position[0].data(), s.p.position[1].data(),
                              s.p.position[2].data()};
  const kernel::RowArrays r(s.a.bonds, s.p);
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
    ASSERT_GT(force_and_break(plain.a.bonds, plain.p, plain.constants()), 0);
    const auto in = fused.constants();
    std::vector<double> energy(fused.p.size(), -1.0);
    std::vector<double> points;
    kernel::pack_points(fused.p, points);
    const kernel::Fields x{
        {fused.p.position[0].data(), fused.p.position[1].data(), fused.p.position[2].data()},
        {fused.p.force_density[0].data(), fused.p.force_density[1].data(),
         fused.p.force_density[2].data()},
        energy.data(),
        points.data()};
    const kernel::RowArrays r(fused.a.bonds, fused.p);
    const kernel::Breaking w{&fused.a.bonds, &in};
    const auto row =
        with_dim(dim, [&](auto d) { return kernel::row_kernel<d(), true, true>(build); });
    for (std::size_t i = 0; i < fused.p.size(); ++i) row(static_cast<std::int64_t>(i), x, r, w);
    EXPECT_EQ(fused.a.bonds.flags, plain.a.bonds.flags);
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
    force_and_break(again.a.bonds, again.p, again.constants(), &sums);
    EXPECT_EQ(strain_energy_of_row_sums(sums, again.p),
              strain_energy_total(again.a.bonds, again.p));
  }
}

// The stretch watch (docs/theory.md §13.1) flags exactly the rows a scan after the pass finds: an
// own bond still intact with (|y|/|ξ|)² at or above the row's limit, for limits below and above
// the row's break limit alike; forces, breaks and bond flags are the pass's without the watch.
TEST_P(ForceKernel, StretchWatchFlagsWhatAScanAfterThePassFinds) {
  const int dim = GetParam();
  std::vector<kernel::Build> builds{kernel::Build::Plain};
  if (kernel::avx2_available()) builds.push_back(kernel::Build::Avx2);
  const auto pass = [&](Stretched& s, kernel::Build build, const kernel::StretchWatch& watch) {
    return every_row(s, dim, build, true, watch);
  };
  for (const auto build : builds) {
    auto watched = stretched_cloud(dim, 17), plain = watched;
    const std::size_t n = watched.p.size();
    std::vector<double> limit(n);
    for (std::size_t i = 0; i < n; ++i)  // 0.3 to 1.3 s0: some rows watch beyond their breaks
      limit[i] =
          bond_law::critical_ratio2((0.3 + 0.2 * static_cast<double>(i % 6)) * watched.a.s0[i]);
    std::vector<std::uint8_t> hit(n, 2);
    const auto broken = pass(watched, build, {limit.data(), hit.data()});
    EXPECT_EQ(broken, pass(plain, build, {}));
    EXPECT_GT(broken, 0);
    EXPECT_EQ(watched.a.bonds.flags, plain.a.bonds.flags);
    for (int d = 0; d < dim; ++d)
      EXPECT_EQ(0, std::memcmp(watched.p.force_density[d].data(), plain.p.force_density[d].data(),
                               n * sizeof(double)));
    const auto& b = watched.a.bonds;
    std::vector<std::uint8_t> scan(n, 0);
    for (std::size_t i = 0; i < n; ++i)
      for (auto k = b.begin(i); k < b.end(i); ++k) {
        const auto j = static_cast<std::size_t>(b.other[k]);
        const double ratio2 = bond_law::stretch_ratio2(bond_law::squared_length(watched.p, i, j),
                                                       b.inverse_length(k));
        if (b.own_intact(k) && ratio2 >= limit[i]) scan[i] = 1;
      }
    EXPECT_EQ(hit, scan) << (build == kernel::Build::Avx2 ? "AVX2" : "plain");
    const auto flagged = std::count(scan.begin(), scan.end(), 1);
    EXPECT_GT(flagged, 0);
    EXPECT_LT(static_cast<std::size_t>(flagged), n);
  }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, ForceKernel, ::testing::Values(1, 2, 3));

}  // namespace
}  // namespace dhpd
