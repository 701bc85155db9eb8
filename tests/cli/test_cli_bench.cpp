// `dhpd bench` on the Kalthoff–Winkler plate: the unit (directed bonds, counted independently
// here), the memory line, and LAMMPS beside it on the same lattice when lmp is installed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <regex>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

/// Directed bonds (ordered pairs with |ξ| ≤ 3.015 dx) of the 128 × 64 × 4 plate without its
/// two notches, by lattice offsets.
long plate_directed_bonds() {
  const int nx = 128, ny = 64, nz = 4;
  auto notch = [&](int i, int j) {
    return i + 0.5 < nx / 4.0 &&
           (std::abs(j + 0.5 - ny / 4.0) < 2.0 || std::abs(j + 0.5 - 3 * ny / 4.0) < 2.0);
  };
  auto site = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz && !notch(i, j);
  };
  long bonds = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!site(i, j, k)) continue;
        for (int c = -3; c <= 3; ++c)
          for (int b = -3; b <= 3; ++b)
            for (int a = -3; a <= 3; ++a) {
              const int r2 = a * a + b * b + c * c;
              if (r2 > 0 && std::sqrt(double(r2)) <= 3.015 && site(i + a, j + b, k + c)) ++bonds;
            }
      }
  return bonds;
}

TEST_F(CliTest, BenchCountsDirectedBondsAndRunsLammpsOnTheSamePlate) {
  const auto o = dhpd({"bench", "--steps", "2", "--repeats", "1", "--threads", "1"});
  ASSERT_EQ(o.code, 0) << o.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.out, m,
                                std::regex(R"((\d+) particles, m = 3.015, (\d+) directed bonds)")))
      << o.out;
  EXPECT_EQ(std::stol(m[1]), 128 * 64 * 4 - 2 * 32 * 4 * 4);
  EXPECT_EQ(std::stol(m[2]), plate_directed_bonds());
  EXPECT_NE(o.out.find("ns/bond/core"), std::string::npos);
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(dhpd state-based +1 +off +[0-9.]+)")))
      << o.out;
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(dhpd correspondence +1 +off +[0-9.]+)")))
      << o.out;
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(dhpd memory: \d+ B per particle)")));
  if (std::system("command -v lmp >/dev/null 2>&1") != 0) GTEST_SKIP() << "lmp not installed";
  EXPECT_NE(o.out.find("LAMMPS peri/pmb      1 rank"), std::string::npos) << o.out;
  EXPECT_EQ(o.out.find("lattices differ"), std::string::npos) << o.out;
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(dhpd is [0-9.]+x faster than LAMMPS)")))
      << o.out;
  EXPECT_TRUE(
      std::regex_search(o.out, std::regex(R"(LAMMPS memory: peak RSS \d+ B per particle)")));
}

TEST_F(CliTest, CheckAndSummaryReportTheAllocatedBytes) {
  const auto c = dhpd({"check", "plate.yaml"});
  ASSERT_EQ(c.code, 0) << c.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      c.out, m,
      std::regex(R"(allocated: \{bytes: (\d+), per_particle: (\d+), .*bond_rows: (\d+), )")))
      << c.out;
  std::smatch dt;
  ASSERT_TRUE(std::regex_search(
      c.out, dt,
      std::regex(
          R"(stable_step: \{run: ([0-9.e+-]+), estimate: lanczos, bound: ([0-9.e+-]+), lanczos: ([0-9.e+-]+),)")))
      << c.out;
  EXPECT_EQ(dt[1], dt[3]);                              // the run takes the Lanczos step
  EXPECT_GT(std::stod(dt[3]), 1.2 * std::stod(dt[2]));  // which the bound would waste
  const auto dir = run_plate("out", {});
  const auto j = read_json(dir / "summary.json");
  const auto& a = j.at("allocated_bytes");
  const auto total = a.at("total").get<std::int64_t>();
  EXPECT_EQ(total, a.at("particle_fields").get<std::int64_t>() +
                       a.at("bond_rows").get<std::int64_t>() + a.at("other").get<std::int64_t>());
  const auto bonds = j.at("bonds").get<std::int64_t>();
  const auto particles = j.at("particles_end").get<std::int64_t>();
  // One row entry per directed bond at least: other, length index, flags and the pair stiffness
  // (the lattice's few distinct lengths are held once, docs/theory.md §18),
  EXPECT_GE(a.at("bond_rows").get<std::int64_t>(), bonds * (4 + 4 + 1 + 4));
  // not 17 B per entry with 1/|ξ| in each (before the length table), nor the 70 bytes of a bond
  // list, dual lists and interaction rows side by side (dhpd 0.x): the rows' index and break
  // thresholds add 24 B per particle, and this plate has about 27 bonds per particle.
  EXPECT_LE(a.at("bond_rows").get<std::int64_t>(), bonds * 13 + particles * 24 + 8 * 1024);
  EXPECT_DOUBLE_EQ(j.at("bytes_per_particle").get<double>(), double(total) / double(particles));
  EXPECT_DOUBLE_EQ(j.at("bytes_per_directed_bond").get<double>(), double(total) / double(bonds));
  EXPECT_EQ(std::stoll(m[3]), a.at("bond_rows").get<std::int64_t>());  // the same body as check's
}

}  // namespace

namespace {

TEST_F(CliTest, BenchOutputsTimesASceneAgainstItselfWithoutOutputs) {
  const auto o = dhpd({"bench", "--outputs", "--repeats", "3", "--scene", "plate.yaml"});
  ASSERT_EQ(o.code, 0) << o.err;
  std::smatch full, bare, ratio, share;
  const std::string number = R"(\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+))";
  ASSERT_TRUE(std::regex_search(o.out, full, std::regex("as the scene is" + number))) << o.out;
  ASSERT_TRUE(std::regex_search(
      o.out, bare, std::regex("one frame; no history, measurement, checkpoint" + number)));
  ASSERT_TRUE(std::regex_search(o.out, ratio, std::regex("ratio, pair by pair" + number)));
  ASSERT_TRUE(std::regex_search(
      o.out, share,
      std::regex(R"(outputs and diagnostics: (-?[0-9.]+) % of the run's wall time)")));
  for (const auto* m : {&full, &bare, &ratio}) {  // median within [min, max], all > 0
    EXPECT_GT(std::stod((*m)[2]), 0.0);
    EXPECT_LE(std::stod((*m)[2]), std::stod((*m)[1]) + 1e-3);
    EXPECT_LE(std::stod((*m)[1]), std::stod((*m)[3]) + 1e-3);
  }
  EXPECT_NEAR(std::stod(share[1]), 100.0 * (1.0 - 1.0 / std::stod(ratio[1])), 0.2);
  // A scene that cannot be read is refused before anything runs, naming it.
  const auto bad = dhpd({"bench", "--outputs", "--scene", "missing.yaml"});
  EXPECT_EQ(bad.code, 2) << bad.out << bad.err;
  EXPECT_NE(bad.err.find("missing.yaml"), std::string::npos) << bad.err;
}

}  // namespace
