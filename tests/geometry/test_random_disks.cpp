// The random-disks generator (CMAME 2017 §5.2 inclusion layouts) keeps its promises: inside the
// box, gaps, cover and clear points, same seed same disks, a too-full box names the failing disk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>

#include "geometry/random_disks.hpp"

namespace dhpd {
namespace {

using geometry::Vec3;

geometry::RandomDisksSpec plate_spec(std::uint64_t seed) {
  geometry::RandomDisksSpec spec;
  spec.box.max = {3.0, 3.0, 0.0};
  spec.count = 25;
  spec.radius_min = 0.1;
  spec.radius_max = 0.25;
  spec.gap = 0.03;
  spec.seed = seed;
  return spec;
}

/// The smallest rim-to-rim distance of the layout (infinite for one disk).
double smallest_gap(const geometry::RandomDisks& d) {
  double gap = 1e300;
  for (std::size_t i = 0; i < d.centers.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      gap = std::min(gap, geometry::norm(d.centers[i] - d.centers[j]) - d.radii[i] - d.radii[j]);
  return gap;
}

TEST(RandomDisks, KeepTheirGapsRadiiAndBox) {
  const auto spec = plate_spec(7);
  const auto d = geometry::place_random_disks(spec);
  ASSERT_FALSE(d.failed);
  ASSERT_EQ(d.centers.size(), 25u);
  EXPECT_GE(smallest_gap(d), spec.gap);
  for (std::size_t k = 0; k < d.centers.size(); ++k) {
    EXPECT_GE(d.radii[k], spec.radius_min);
    EXPECT_LE(d.radii[k], spec.radius_max);
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(d.centers[k][a] - d.radii[k], spec.box.min[a]);
      EXPECT_LE(d.centers[k][a] + d.radii[k], spec.box.max[a]);
    }
  }
  // The radii spread over their range (not all at one end).
  const auto [lo, hi] = std::minmax_element(d.radii.begin(), d.radii.end());
  EXPECT_LT(*lo, 0.13);
  EXPECT_GT(*hi, 0.22);
}

TEST(RandomDisks, SameSeedSameDisksOtherSeedOtherDisks) {
  const auto a = geometry::place_random_disks(plate_spec(1));
  const auto b = geometry::place_random_disks(plate_spec(1));
  const auto c = geometry::place_random_disks(plate_spec(2));
  EXPECT_EQ(a.centers, b.centers);
  EXPECT_EQ(a.radii, b.radii);
  EXPECT_NE(a.centers, c.centers);
  EXPECT_EQ(a.shape(), b.shape());
}

TEST(RandomDisks, CoverPointsLieInsideAndClearPointsOutside) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    auto spec = plate_spec(seed);
    spec.cover = {{1.0, 1.0, 0.0}, {2.2, 0.6, 0.0}};
    spec.clear = {{1.5, 1.0, 0.0}};
    const auto d = geometry::place_random_disks(spec);
    ASSERT_FALSE(d.failed) << "seed " << seed;
    const auto shape = d.shape();
    for (std::size_t k = 0; k < spec.cover.size(); ++k) {
      EXPECT_LE(geometry::norm(spec.cover[k] - d.centers[k]), d.radii[k]);  // the k-th disk
      EXPECT_TRUE(shape.contains(spec.cover[k], 2));
    }
    for (std::size_t k = 0; k < d.centers.size(); ++k)
      EXPECT_GE(geometry::norm(spec.clear[0] - d.centers[k]), d.radii[k] + spec.gap);
  }
}

TEST(RandomDisks, ATooFullBoxNamesTheDiskThatFoundNoPlace) {
  auto spec = plate_spec(3);
  spec.count = 200;  // 200 disks of mean area 0.1 in a box of area 9
  const auto d = geometry::place_random_disks(spec);
  ASSERT_TRUE(d.failed);
  EXPECT_EQ(static_cast<std::size_t>(*d.failed), d.centers.size());
  EXPECT_GT(d.covered_fraction(spec.box), 0.3);
  EXPECT_LT(d.covered_fraction(spec.box), 0.7);
}

}  // namespace
}  // namespace dhpd
