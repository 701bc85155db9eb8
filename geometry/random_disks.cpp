// Random sequential addition of disks (CMAME 2017 §5.2 inclusion layouts; docs/scenes.md,
// "Shapes", random-disks).
#include "geometry/random_disks.hpp"

#include <cmath>
#include <numbers>
#include <random>

namespace dhpd::geometry {
namespace {

/// A uniform double in [0, 1) from the top 53 bits of one draw (fixed on every platform).
double unit(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + unit(rng) * (hi - lo);
}

class Placer {
 public:
  explicit Placer(const RandomDisksSpec& spec) : spec_(spec), rng_(spec.seed) {}

  RandomDisks place() {
    for (int k = 0; k < spec_.count; ++k) {
      const double r = uniform(rng_, spec_.radius_min, spec_.radius_max);
      const auto k_size = static_cast<std::size_t>(k);
      const Vec3* cover = k_size < spec_.cover.size() ? &spec_.cover[k_size] : nullptr;
      if (!place_one(r, cover)) {
        out_.failed = k;
        break;
      }
    }
    return out_;
  }

 private:
  bool place_one(double r, const Vec3* cover) {
    for (int draw = 0; draw < kRandomDiskDraws; ++draw) {
      // A covering disk's centre lies within r/2 of the point on each axis (so within 0.71 r).
      const double x = cover ? (*cover)[0] + uniform(rng_, -0.5 * r, 0.5 * r)
                             : uniform(rng_, spec_.box.min[0] + r, spec_.box.max[0] - r);
      const double y = cover ? (*cover)[1] + uniform(rng_, -0.5 * r, 0.5 * r)
                             : uniform(rng_, spec_.box.min[1] + r, spec_.box.max[1] - r);
      const Vec3 c{x, y, 0.0};
      if (fits(c, r)) {
        out_.centers.push_back(c);
        out_.radii.push_back(r);
        return true;
      }
    }
    return false;
  }

  bool fits(const Vec3& c, double r) const {
    const Box& b = spec_.box;
    if (c[0] - r < b.min[0] || c[0] + r > b.max[0] || c[1] - r < b.min[1] || c[1] + r > b.max[1])
      return false;
    for (std::size_t j = 0; j < out_.centers.size(); ++j)
      if (norm(c - out_.centers[j]) < r + out_.radii[j] + spec_.gap) return false;
    for (const Vec3& p : spec_.clear)
      if (norm(c - p) < r + spec_.gap) return false;
    return true;
  }

  const RandomDisksSpec& spec_;
  std::mt19937_64 rng_;
  RandomDisks out_;
};

}  // namespace

double RandomDisks::covered_fraction(const Box& box) const {
  double area = 0.0;
  for (const double r : radii) area += std::numbers::pi * r * r;
  return area / box.measure(2);
}

Shape RandomDisks::shape() const {
  std::vector<Shape> disks;
  for (std::size_t k = 0; k < centers.size(); ++k)
    disks.push_back(Shape::ball(centers[k], radii[k]));
  return Shape::union_of(disks);
}

RandomDisks place_random_disks(const RandomDisksSpec& spec) {
  return Placer(spec).place();
}

}  // namespace dhpd::geometry
