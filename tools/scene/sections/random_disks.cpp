// The `random-disks` shape: non-overlapping disks placed at random from a seed (CMAME 2017 §5.2
// inclusion layouts; schema in docs/scenes.md, "Shapes").
#include <fmt/format.h>

#include "geometry/random_disks.hpp"
#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

constexpr std::int64_t kMaxRandomDisks = 1000;

std::vector<geometry::Vec3> points_of(const std::optional<Cursor>& c) {
  std::vector<geometry::Vec3> points;
  if (c)
    for (const auto& item : c->list()) points.push_back(item.point(2));
  return points;
}

/// `radius: [smallest, largest]`, both > 0, smallest <= largest, the largest fitting the box.
void read_radii(const Cursor& c, geometry::RandomDisksSpec& spec) {
  const auto bounds = c.list_of_size(2, "[smallest, largest] radius");
  const auto radius = [](const Cursor& r, const char* which) {
    const double value = r.number();
    if (!(value > 0.0))
      r.fail(fmt::format("the {} radius must be > 0, got {}", which, r.text()), "> 0");
    return value;
  };
  spec.radius_min = radius(bounds[0], "smallest");
  spec.radius_max = radius(bounds[1], "largest");
  if (spec.radius_min > spec.radius_max)
    c.fail(fmt::format("the smallest radius {} is larger than the largest {}", spec.radius_min,
                       spec.radius_max),
           "[smallest, largest] with smallest <= largest");
  const auto axes = axis_names(2);
  for (int a = 0; a < 2; ++a) {
    const double extent = spec.box.max[a] - spec.box.min[a];
    if (2.0 * spec.radius_max > extent)
      c.fail(fmt::format("a disk of radius {} does not fit in the box, whose {} extent is {}",
                         spec.radius_max, axes[static_cast<std::size_t>(a)], extent),
             fmt::format("largest radius <= {}", 0.5 * extent));
  }
}

std::uint64_t seed_of(const Cursor& c) {
  const std::int64_t seed = c.integer();
  if (seed < 0) c.fail(fmt::format("seed must be an integer >= 0, got {}", c.text()), ">= 0");
  return static_cast<std::uint64_t>(seed);
}

/// Fails at `count` (or at the cover point the failed disk was to hold).
[[noreturn]] void refuse_layout(const MapView& map, const geometry::RandomDisksSpec& spec,
                                const geometry::RandomDisks& disks) {
  const int k = *disks.failed;
  const std::string advice = "fewer or smaller disks, a smaller gap, a larger box, another seed";
  if (static_cast<std::size_t>(k) < spec.cover.size())
    map.require("cover").list()[static_cast<std::size_t>(k)].fail(
        fmt::format("no disk covering this point fits in {} draws (disk {} of {}): it must fit in "
                    "the box, keep the gap to the disks before it and to the clear points",
                    geometry::kRandomDiskDraws, k + 1, spec.count),
        advice);
  map.require("count").fail(
      fmt::format("could place only {} of {} disks: disk {} found no place in {} draws (the {} "
                  "placed cover {:.1f} % of the box)",
                  k, spec.count, k + 1, geometry::kRandomDiskDraws, k,
                  100.0 * disks.covered_fraction(spec.box)),
      advice);
}

}  // namespace

geometry::Shape read_random_disks(const MapView& map) {
  geometry::RandomDisksSpec spec;
  spec.box.min = map.require("min").point(2);
  const Cursor max = map.require("max");
  spec.box.max = max.point(2);
  check_box(max, spec.box, 2);
  const Cursor count = map.require("count");
  const std::int64_t n = positive_integer(count);
  if (n > kMaxRandomDisks)
    count.fail(fmt::format("count must be at most {}, got {}", kMaxRandomDisks, count.text()),
               fmt::format("1 to {}", kMaxRandomDisks));
  spec.count = static_cast<int>(n);
  read_radii(map.require("radius"), spec);
  spec.gap = non_negative_number(map.require("gap"));
  spec.seed = seed_of(map.require("seed"));
  spec.cover = points_of(map.get("cover"));
  spec.clear = points_of(map.get("clear"));
  if (spec.cover.size() > static_cast<std::size_t>(spec.count))
    map.require("cover").fail(
        fmt::format("{} points to cover but only {} disks", spec.cover.size(), spec.count),
        fmt::format("at most count = {} points", spec.count));
  const geometry::RandomDisks disks = geometry::place_random_disks(spec);
  if (disks.failed) refuse_layout(map, spec, disks);
  return disks.shape();
}

}  // namespace dhpd::scene::detail
