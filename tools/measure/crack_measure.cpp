// Crack tip, speed, angle and branching from the damage field (IJNME 2016 eq. 59–60; docs/theory.md
// §15).
#include "tools/measure/crack_measure.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <queue>
#include <utility>

namespace dhpd::measure {
namespace {

/// At most this many clusters of a bin (the largest) enter the search for separated ones.
constexpr std::size_t kMaxClusters = 24;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Union-find root with path halving.
std::int32_t find_root(std::vector<std::int32_t>& root, std::int32_t n) {
  while (root[n] != n) n = root[n] = root[root[n]];
  return n;
}

/// The largest subset of points pairwise farther apart than a distance (exact branch and bound;
/// few points).
class SeparatedSubset {
 public:
  SeparatedSubset(const std::vector<Vec3>& points, double separation) : near_(points.size(), 0) {
    for (std::size_t i = 0; i < points.size(); ++i)
      for (std::size_t j = 0; j < points.size(); ++j)
        if (i != j && geometry::norm(points[i] - points[j]) <= separation) near_[i] |= 1u << j;
    const std::uint32_t all = points.size() >= 32 ? ~0u : (std::uint32_t{1} << points.size()) - 1u;
    grow(0, all);
  }
  std::uint32_t chosen() const { return best_; }

 private:
  void grow(std::uint32_t chosen, std::uint32_t open) {
    if (std::popcount(chosen) + std::popcount(open) <= std::popcount(best_)) return;
    if (open == 0) {
      best_ = chosen;
      return;
    }
    const int v = std::countr_zero(open);
    const std::uint32_t bit = std::uint32_t{1} << v;
    grow(chosen | bit, open & ~near_[v] & ~bit);
    grow(chosen, open & ~bit);
  }
  std::vector<std::uint32_t> near_;
  std::uint32_t best_ = 0;
};

/// The clusters of one bin (nodes with the same union-find root), largest first, and how many of
/// them are pairwise farther apart than `separation` × the bin's largest horizon.
Branches separated_clusters(const std::vector<std::int32_t>& members,
                            std::vector<std::int32_t>& root, const DamageGraph& g,
                            const ParticleStore& p, double separation,
                            const std::optional<Vec3>& front) {
  std::map<std::int32_t, std::pair<Vec3, std::size_t>> sums;  // root -> (Σ X, count)
  double horizon = 0.0;
  for (const auto n : members) {
    const auto i = static_cast<std::size_t>(g.particle[n]);
    auto& [sum, count] = sums[find_root(root, n)];
    sum = sum + point_of(p.reference_position, i);
    ++count;
    horizon = std::max(horizon, p.horizon[i]);
  }
  std::vector<std::pair<std::size_t, Vec3>> clusters;  // (size, centroid)
  for (const auto& [r, s] : sums)
    clusters.emplace_back(s.second, (1.0 / static_cast<double>(s.second)) * s.first);
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  if (clusters.size() > kMaxClusters) clusters.resize(kMaxClusters);
  std::vector<Vec3> centroids, apart;  // apart: separations across the front only
  const Vec3 f = front ? (1.0 / geometry::norm(*front)) * *front : Vec3{0, 0, 0};
  for (const auto& c : clusters) {
    centroids.push_back(c.second);
    apart.push_back(c.second - geometry::dot(c.second, f) * f);
  }
  const std::uint32_t chosen = SeparatedSubset(apart, separation * horizon).chosen();
  Branches out;
  for (std::size_t k = 0; k < centroids.size(); ++k)
    if (chosen & (std::uint32_t{1} << k)) out.centroids.push_back(centroids[k]);
  out.count = static_cast<int>(out.centroids.size());
  return out;
}

}  // namespace

CrackPath crack_path(const DamageGraph& g, const ParticleStore& p, const Vec3& notch_tip,
                     const geometry::Shape* region) {
  CrackPath c;
  c.path.assign(g.size(), kInfinity);
  std::vector<char> outside(g.size(), 0);
  for (std::size_t n = 0; region && n < g.size(); ++n)
    outside[n] = !region->contains(point_of(p.reference_position, g.particle[n]), p.dim());
  using Item = std::pair<double, std::int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t n = 0; n < g.size(); ++n) {
    const auto i = static_cast<std::size_t>(g.particle[n]);
    const double d = geometry::norm(point_of(p.reference_position, i) - notch_tip);
    if (d > p.horizon[i] || outside[n]) continue;
    c.path[n] = d;
    queue.emplace(d, static_cast<std::int32_t>(n));
  }
  while (!queue.empty()) {
    const auto [d, n] = queue.top();
    queue.pop();
    if (d > c.path[n]) continue;
    for (auto l = g.offset[n]; l < g.offset[n + 1]; ++l) {
      const auto m = g.neighbor[l];
      const double through = d + g.length[l];
      if (through >= c.path[m] || outside[m]) continue;
      c.path[m] = through;
      queue.emplace(through, m);
    }
  }
  // Farthest along the path; equal paths go to the smaller particle id (independent of order).
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (!std::isfinite(c.path[n])) continue;
    const auto t = static_cast<std::size_t>(c.tip);
    if (c.tip < 0 || c.path[n] > c.path[t] ||
        (c.path[n] == c.path[t] && p.id[g.particle[n]] < p.id[g.particle[t]]))
      c.tip = static_cast<std::int32_t>(n);
  }
  return c;
}

Branches count_branches(const DamageGraph& g, const CrackPath& crack, const ParticleStore& p,
                        double separation, const std::optional<Vec3>& front) {
  double width = 0.0;
  for (std::size_t n = 0; n < g.size(); ++n)
    if (std::isfinite(crack.path[n])) width = std::max(width, p.horizon[g.particle[n]]);
  if (width == 0.0) return {};
  std::vector<std::int64_t> bin(g.size(), -1);
  std::map<std::int64_t, std::vector<std::int32_t>> bins;
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (!std::isfinite(crack.path[n])) continue;
    bin[n] = static_cast<std::int64_t>(std::floor(crack.path[n] / width));
    bins[bin[n]].push_back(static_cast<std::int32_t>(n));
  }
  std::vector<std::int32_t> root(g.size());
  std::iota(root.begin(), root.end(), 0);
  for (std::size_t n = 0; n < g.size(); ++n)
    for (auto l = g.offset[n]; bin[n] >= 0 && l < g.offset[n + 1]; ++l)
      if (bin[g.neighbor[l]] == bin[n])
        root[find_root(root, static_cast<std::int32_t>(n))] = find_root(root, g.neighbor[l]);
  Branches best;
  for (const auto& [b, members] : bins) {
    auto found = separated_clusters(members, root, g, p, separation, front);
    if (found.count > best.count) best = std::move(found);
  }
  return best;
}

double angle_between_deg(const Vec3& a, const Vec3& b) {
  if (geometry::norm(a) == 0.0 || geometry::norm(b) == 0.0)
    return std::numeric_limits<double>::quiet_NaN();
  return std::atan2(geometry::norm(geometry::cross(a, b)), geometry::dot(a, b)) * 180.0 /
         std::numbers::pi;
}

/// The chord from the notch tip with its component along the notch front removed (none without a
/// front): a through crack's angle in its plate, whatever the tip's height in the thickness.
Vec3 across_front(const Vec3& chord, const std::optional<Vec3>& front) {
  if (!front) return chord;
  const Vec3 f = (1.0 / geometry::norm(*front)) * *front;
  return chord - geometry::dot(chord, f) * f;
}

double rayleigh_speed_near(const ParticleStore& p, const std::vector<Material>& materials,
                           const Section& section, const Vec3& at) {
  std::size_t nearest = 0;
  double best = kInfinity;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double d = geometry::norm(point_of(p.reference_position, i) - at);
    if (d < best) best = d, nearest = i;
  }
  return rayleigh_speed(materials.at(static_cast<std::size_t>(p.material[nearest])), section);
}

CrackTracker::CrackTracker(Settings settings) : s_(std::move(settings)), tracks_(s_.tips.size()) {}

std::vector<TipRow> CrackTracker::measure(const ParticleStore& p, std::int64_t step, double time,
                                          const std::optional<Revision>& revision,
                                          const double* damage) {
  DamageGraph built;
  if (!revision) built = damage_graph(p, s_.damage_threshold);
  const DamageGraph& g = revision ? graph_.update(p, *revision, damage) : built;
  const auto version = revision ? std::optional(graph_.version()) : std::nullopt;
  std::vector<TipRow> rows;
  for (std::size_t k = 0; k < s_.tips.size(); ++k)
    rows.push_back(measure_tip(g, p, k, step, time, version));
  return rows;
}

const CrackTracker::CrackShape& CrackTracker::shape_of(const DamageGraph& g, const ParticleStore& p,
                                                       std::size_t k,
                                                       std::optional<std::uint64_t> graph_version) {
  shapes_.resize(s_.tips.size());
  auto& shape = shapes_[k];
  if (graph_version && shape.graph_version == graph_version) return shape;
  const Tip& tip = s_.tips[k];
  shape.crack = crack_path(g, p, tip.at, tip.region ? &*tip.region : nullptr);
  shape.branches = count_branches(g, shape.crack, p, s_.branch_separation, tip.front);
  shape.graph_version = graph_version;
  return shape;
}

TipRow CrackTracker::measure_tip(const DamageGraph& g, const ParticleStore& p, std::size_t k,
                                 std::int64_t step, double time,
                                 std::optional<std::uint64_t> graph_version) {
  const Tip& tip = s_.tips[k];
  Track& t = tracks_[k];
  const CrackShape& shape = shape_of(g, p, k, graph_version);
  const CrackPath& crack = shape.crack;
  TipRow r{step, time, k, tip.at};
  double horizon = kInfinity;  // nothing cracked: never initiated
  if (crack.tip >= 0) {
    const auto i = static_cast<std::size_t>(g.particle[crack.tip]);
    r.x = point_of(p.reference_position, i);
    r.path_length = crack.path[crack.tip];
    horizon = p.horizon[i];
  }
  r.distance = geometry::norm(r.x - tip.at);
  r.angle_deg = angle_between_deg(tip.direction, across_front(r.x - tip.at, tip.front));
  t.time.push_back(time);
  t.x.push_back(r.x);
  t.path.push_back(r.path_length);
  const std::size_t l = t.time.size() - 1;
  const std::size_t back = std::min(static_cast<std::size_t>(s_.smoothing), l);
  if (back > 0 && t.time[l] > t.time[l - back])
    r.speed = geometry::norm(t.x[l] - t.x[l - back]) / (t.time[l] - t.time[l - back]);
  // Initiation: the crack exists (a damaged particle linked to the notch tip). It runs once its
  // tip is more than one horizon out; speeds over intervals that start earlier follow damage
  // forming around the notch tip (or appearing at once above the threshold): they are left out.
  if (!t.initiated && std::isfinite(horizon)) t.initiated = l;
  if (!t.running && r.distance > horizon) t.running = l;
  if (t.running && l - back >= *t.running && back > 0)
    t.max_speed = std::max(t.max_speed.value_or(0.0), r.speed);
  t.angle_deg = std::isnan(r.angle_deg) ? std::nullopt : std::optional<double>(r.angle_deg);
  if (!t.initial_angle && r.distance >= kInitialHorizons * horizon) t.initial_angle = t.angle_deg;
  const Branches& branches = shape.branches;
  r.branches = branches.count;
  if (branches.count > std::max(t.most_branches, 1)) {  // 0 -> 1 is the crack, not a branch
    t.branch_times.push_back(time);
    t.branch_speeds.push_back(r.speed);
    t.branch_positions.insert(t.branch_positions.end(), branches.centroids.begin(),
                              branches.centroids.end());
  }
  t.most_branches = std::max(t.most_branches, branches.count);
  return r;
}

std::vector<CrackSummary> CrackTracker::summary() const {
  std::vector<CrackSummary> out;
  for (std::size_t k = 0; k < s_.tips.size(); ++k) {
    const Track& t = tracks_[k];
    CrackSummary c;
    c.name = s_.tips[k].name;
    c.angle_deg = t.angle_deg;
    c.max_speed = t.max_speed;
    c.branch_times = t.branch_times;
    c.branch_speeds = t.branch_speeds;
    c.initial_angle_deg = t.initial_angle;
    c.branch_positions = t.branch_positions;
    c.most_branches = t.most_branches;
    c.tip = t.x.empty() ? s_.tips[k].at : t.x.back();
    if (t.initiated) c.initiation_time = t.time[*t.initiated];
    if (t.running) {
      const std::size_t i = *t.running;
      if (t.time.back() > t.time[i])
        c.mean_speed = (t.path.back() - t.path[i]) / (t.time.back() - t.time[i]);
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace dhpd::measure
