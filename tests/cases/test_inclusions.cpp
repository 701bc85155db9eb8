// The inclusion plate of CMAME 2017 §5.2 (cases/inclusions_cmame_case{1,2,3}.yaml, Figs. 14-16):
// where the crack runs first (matrix or inclusion, by where the notch tip lies), and what a
// faster pull changes (more broken bonds and branches, cracks through inclusions away from the
// notch). Measured on the last frame (`material`, `damage`) and summary.json. The fast tests run
// the cases at Δx = 37.5 µm (6,400 particles, seconds); InclusionsFullResolution runs them as
// shipped (40,000 particles, minutes) only when DHPD_VERIFICATION is set (ctest label
// `verification`, tests/CMakeLists.txt).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

constexpr double kTipX = 0.001, kTipY = 0.0015;  // the notch tip of the three scenes
constexpr double kNear = 2.0e-4;                 // "first": cracked within 0.2 mm beyond the tip
constexpr double kFar = 5.0e-4;    // beyond every disk that can hold the tip (2 × largest radius)
constexpr double kCracked = 0.35;  // φ of a cracked particle (the measure block's default)
constexpr int kInclusion = 1;      // material index: `inclusion` is the second of `materials`

/// What a finished run of one case shows.
struct PlateCrack {
  int near = 0, near_inclusion = 0;  ///< cracked particles within kNear of the tip, x > tip
  int far = 0, far_inclusion = 0;    ///< cracked particles farther than kFar from the tip
  long long broken_bonds = 0;
  int most_branches = 0;
  double initiation_time = -1.0;
  json summary;
  double near_inclusion_share() const { return near > 0 ? double(near_inclusion) / near : -1.0; }
};

/// Counts the cracked particles of the last frame of run directory `dir` near and far from the tip.
void count_cracked(const fs::path& dir, const std::string& name, PlateCrack& out) {
  const auto frames = dhpd::io::read_pvd((dir / (name + ".pvd")).string());
  ASSERT_FALSE(frames.empty());
  const auto frame = dhpd::io::read_frame((dir / frames.back().second).string());
  const auto& damage = frame.fields.at("damage").second;
  const auto& material = frame.fields.at("material").second;
  for (std::size_t i = 0; i < damage.size(); ++i) {
    if (damage[i] < kCracked) continue;
    const double x = frame.points[3 * i], y = frame.points[3 * i + 1];  // reference positions
    const double r = std::hypot(x - kTipX, y - kTipY);
    const bool inclusion = static_cast<int>(material[i]) == kInclusion;
    if (r <= kNear && x > kTipX) out.near += 1, out.near_inclusion += inclusion;
    if (r > kFar) out.far += 1, out.far_inclusion += inclusion;
  }
}

class InclusionPlate : public CliTest {
 public:
  /// Runs cases/inclusions_cmame_caseN.yaml with `sets` and measures it.
  PlateCrack run_case(int n, std::vector<std::string> sets) {
    const std::string name = "inclusions_cmame_case" + std::to_string(n);
    const std::string out = name + "_" + std::to_string(++runs_);
    const auto o = dhpd(
        {"run", std::string(DHPD_SOURCE_DIR) + "/cases/" + name + ".yaml", "-o", out, "-q"}, sets);
    EXPECT_EQ(o.code, 0) << o.err;
    PlateCrack c;
    c.summary = read_json(dir_ / out / "summary.json");
    const auto& crack = c.summary.at("cracks").at(0);
    c.broken_bonds = c.summary.at("broken_bonds").get<long long>();
    c.most_branches = crack.at("most_branches").get<int>();
    if (!crack.at("initiation_time").is_null())
      c.initiation_time = crack.at("initiation_time").get<double>();
    count_cracked(dir_ / out, name, c);
    std::printf(
        "case %d: initiation %.2f us, broken bonds %lld, most branches %d, first %.1f mm: %d "
        "cracked (%d inclusion), beyond %.1f mm: %d cracked (%d inclusion), wall %.1f s\n",
        n, c.initiation_time * 1e6, c.broken_bonds, c.most_branches, kNear * 1e3, c.near,
        c.near_inclusion, kFar * 1e3, c.far, c.far_inclusion,
        c.summary.at("wall_seconds").get<double>());
    return c;
  }
  int runs_ = 0;
};

/// The per-material counts of summary.json add up to the run's totals.
void expect_material_counts_add_up(const json& s) {
  long long particles = 0, bonds = 0, broken = 0;
  for (const auto& [name, m] : s.at("materials").items()) {
    particles += m.at("particles").get<long long>();
    bonds += m.at("bonds").get<long long>();
    broken += m.at("broken_bonds").get<long long>();
    EXPECT_LE(m.at("damaged_particles").get<long long>(), m.at("particles").get<long long>());
  }
  EXPECT_EQ(particles, s.at("particles_end").get<long long>());
  EXPECT_EQ(bonds, s.at("bonds").get<long long>());
  EXPECT_EQ(broken, s.at("broken_bonds").get<long long>());
}

/// Checks (a) and (b)-(c) of the brief on the three cases run with `sets` at three safeties:
/// where a crack runs and how much breaks hold in every run, but which inclusions far from the
/// notch a branch happens to cut is chaotic in the time step (0 to 9 at full resolution between
/// safeties 0.4, 0.5, 0.6; docs/verification.md), so (c) is checked on the three runs' sum.
/// `far_factor`: how many times more cracked inclusion particles away from the notch case III
/// must show than case II.
void check_cases(InclusionPlate& t, const std::vector<std::string>& sets, double far_factor) {
  int fast_far_inclusion = 0, slow_far_inclusion = 0;
  for (const char* safety : {"0.4", "0.5", "0.6"}) {
    auto with_safety = sets;
    with_safety.push_back(std::string("time.safety=") + safety);
    const PlateCrack tip_in_matrix = t.run_case(1, with_safety);
    const PlateCrack tip_in_inclusion = t.run_case(2, with_safety);
    const PlateCrack fast = t.run_case(3, with_safety);
    for (const PlateCrack* c : {&tip_in_matrix, &tip_in_inclusion, &fast}) {
      EXPECT_GT(c->initiation_time, 0.0);  // every notch starts a crack
      EXPECT_GE(c->near, 8);               // ... that runs past the first 0.2 mm
      expect_material_counts_add_up(c->summary);
    }
    // (a) The crack runs first through the phase the notch tip lies in (Fig. 16b, c).
    EXPECT_LE(tip_in_matrix.near_inclusion_share(), 0.1) << "safety " << safety;
    EXPECT_GE(tip_in_inclusion.near_inclusion_share(), 0.9) << "safety " << safety;
    // (b) Pulled 4x faster, the same layout breaks more bonds and branches more.
    EXPECT_GT(fast.broken_bonds, 1.5 * tip_in_inclusion.broken_bonds) << "safety " << safety;
    EXPECT_GT(fast.most_branches, tip_in_inclusion.most_branches) << "safety " << safety;
    fast_far_inclusion += fast.far_inclusion;
    slow_far_inclusion += tip_in_inclusion.far_inclusion;
  }
  // (c) ... and its cracks cut through inclusions away from the notch's own inclusion.
  std::printf(
      "cracked inclusion particles beyond %.1f mm, three safeties: case II %d, case III %d\n",
      kFar * 1e3, slow_far_inclusion, fast_far_inclusion);
  EXPECT_GE(fast_far_inclusion, far_factor * std::max(slow_far_inclusion, 1));
}

TEST_F(InclusionPlate, CrackStartsInTheTipsPhaseAndAFasterPullBranchesThroughInclusions) {
  check_cases(*this, {"body.0.spacing=3.75e-5"}, 2.0);
}

TEST_F(InclusionPlate, InclusionParticlesFillTheGeneratedDisks) {
  // The inclusion particles of case I (random-disks, seed 1) stand for the disks' area, up to
  // the lattice cells on their rims (Δx = 15 µm against radii of 100-250 µm).
  const std::string file = std::string(DHPD_SOURCE_DIR) + "/cases/inclusions_cmame_case1.yaml";
  const auto scene = dhpd::scene::load_scene(file);
  const auto& disks = scene.material_regions.at(0).region;
  double area = 0.0;
  for (const auto& node : disks.nodes())
    if (node.kind == dhpd::geometry::Shape::Kind::Ball) area += M_PI * node.radius * node.radius;
  const auto o = dhpd({"run", file, "-o", "layout", "-q"}, {"time.steps=1", "output.every=1"});
  ASSERT_EQ(o.code, 0) << o.err;
  const auto s = read_json(dir_ / "layout" / "summary.json");
  const double particles = s.at("materials").at("inclusion").at("particles").get<double>();
  const double dx = 1.5e-5;
  std::printf("25 disks: %.4f mm2; %.0f inclusion particles: %.4f mm2\n", area * 1e6, particles,
              particles * dx * dx * 1e6);
  EXPECT_NEAR(particles * dx * dx, area, 0.01 * area);
  EXPECT_EQ(s.at("materials").at("inclusion").at("broken_bonds").get<long long>(), 0);
}

TEST_F(InclusionPlate, FullResolution) {
  if (std::getenv("DHPD_VERIFICATION") == nullptr)
    GTEST_SKIP() << "40,000 particles, minutes: set DHPD_VERIFICATION=1 (ctest -L verification)";
  check_cases(*this, {}, 5.0);
}

}  // namespace
