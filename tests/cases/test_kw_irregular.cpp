// CMAME 2017 §6 (Table 2), reduced: cases I (constant horizon) and II (dual horizon) of
// cases/kw_irregular/ on coarser graded meshes with the same size ratio 3.1. The full six-case
// study is the verification test KwIrregularStudy (tests/CMakeLists.txt).
#include <algorithm>
#include <cmath>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class KwIrregular : public CliTest {
 protected:
  /// The early crack angle of each tip of cases/kw_irregular/FILE run on a mesh of size `size`
  /// (grading from the middle between the notch tips, size ratio 3.1 to the farthest corner, as
  /// the case): the median chord angle while the tip lay 10 to 20 mm from its notch tip (as
  /// tools/python/study_angles.py with early_distance 0.02). Runs to 60 µs, past the 20 mm.
  std::vector<double> early_angles(const std::string& file, double size) {
    const std::string out = file.substr(0, file.find('_')) + "_" + std::to_string(size);
    const double rate = 2.1 / std::hypot(0.05, 0.1) * size;  // h = 3.1 size at (0 or 0.1, ±0.1)
    const auto o =
        dhpd({"run", std::string(DHPD_SOURCE_DIR) + "/cases/kw_irregular/" + file, "-o", out, "-q"},
             {"body.0.mesh={size: " + std::to_string(size) +
                  ", grading: {from: [0.05, 0.0], rate: " + std::to_string(rate) + "}}",
              "time.end=6e-5", "output.frames=1", "output.checkpoint_every=0"});
    EXPECT_EQ(o.code, 0) << o.err;
    const auto csv = read_history(dir_ / out / "cracks.csv");  // tip,...,distance,...,angle_deg
    std::vector<std::vector<double>> band(2);
    for (const auto& row : csv.rows) {
      const double distance = std::stod(row.at(6));
      if (distance >= 0.01 && distance <= 0.02)
        band.at(row.at(2) == "upper" ? 0 : 1).push_back(std::stod(row.at(9)));
    }
    std::vector<double> median;
    for (auto& b : band) {
      EXPECT_FALSE(b.empty()) << file << ": the crack never lay 10 to 20 mm from the notch";
      if (b.empty()) return {};
      std::sort(b.begin(), b.end());
      median.push_back(b.size() % 2 ? b[b.size() / 2]
                                    : 0.5 * (b[b.size() / 2 - 1] + b[b.size() / 2]));
    }
    return median;
  }

  /// Mean distance of the angles from the experiment's 65–70° (0 inside).
  static double off_window(const std::vector<double>& angles) {
    double sum = 0;
    for (const double a : angles) sum += std::max({65.0 - a, 0.0, a - 70.0});
    return sum / static_cast<double>(angles.size());
  }
};

// Measured (early angles, upper / lower): size 2 mm (3,440 nodes) I 44.9 / 44.9°, II 53.0 /
// 53.4°; size 1.5 mm (6,041 nodes) I 46.4 / 49.5°, II 46.4 / 60.7°. The same ordering holds on
// every mesh tried (sizes 0.9 to 2.2 mm, 11 meshes; the case's 1 mm: I 52.1 / 51.4°, II 61.5 /
// 58.3°; paper I 56.1 / 57.6°, II 67.6 / 64.7°); the final chord angles do not order reliably.
TEST_F(KwIrregular, DualHorizonCracksStartCloserTo65To70DegreesThanConstantHorizon) {
  for (const double size : {0.002, 0.0015}) {
    const auto constant = early_angles("I_2d_constant_horizon.yaml", size);
    const auto dual = early_angles("II_2d_dual_horizon.yaml", size);
    ASSERT_EQ(constant.size(), 2u);
    ASSERT_EQ(dual.size(), 2u);
    std::printf(
        "mesh %.1f mm: early angles constant horizon %.1f / %.1f deg (%.1f deg off "
        "65-70), dual horizon %.1f / %.1f deg (%.1f deg off)\n",
        size * 1e3, constant[0], constant[1], off_window(constant), dual[0], dual[1],
        off_window(dual));
    EXPECT_LT(off_window(dual), off_window(constant)) << "mesh size " << size;
  }
}

}  // namespace
