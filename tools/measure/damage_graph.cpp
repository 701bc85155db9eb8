// The damage graph of the crack measurements (docs/theory.md §15), at once and growing.
#include "tools/measure/damage_graph.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "engine/discretization/neighbor_search.hpp"

namespace dhpd::measure {
namespace {

/// Two damaged particles are linked within this many (larger) spacings: the lattice neighbours
/// and diagonal neighbours (√2 Δx), not the next-but-one (2 Δx).
constexpr double kLinkFactor = 1.5;

/// |X_j − X_i| when i and j are linked, else a negative number.
double link_length(const ParticleStore& p, std::size_t i, std::size_t j) {
  const double d =
      geometry::norm(point_of(p.reference_position, j) - point_of(p.reference_position, i));
  return d <= kLinkFactor * std::max(p.spacing[i], p.spacing[j]) ? d : -1.0;
}

/// Writes the CSR of g from (node, neighbour node, length) triples, each node's links sorted by
/// neighbour node.
void write_csr(DamageGraph& g, std::vector<std::pair<std::int32_t, double>>* per_node) {
  g.offset.assign(1, 0);
  g.neighbor.clear();
  g.length.clear();
  for (std::size_t n = 0; n < g.size(); ++n) {
    auto& links = per_node[n];
    std::sort(links.begin(), links.end());
    for (const auto& [m, d] : links) g.neighbor.push_back(m), g.length.push_back(d);
    g.offset.push_back(g.neighbor.size());
  }
}

}  // namespace

DamageGraph damage_graph(const ParticleStore& p, double threshold) {
  DamageGraph g;
  double widest = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.damage[i] >= threshold) {
      g.particle.push_back(static_cast<std::int32_t>(i));
      widest = std::max(widest, p.spacing[i]);
    }
  g.offset.assign(1, 0);
  if (g.particle.empty()) return g;
  VectorArray points;
  for (const auto i : g.particle)
    for (int a = 0; a < 3; ++a) points[a].push_back(p.reference_position[a][i]);
  const NeighborSearch search(points, p.dim());
  // The search keeps |ξ| ≤ radius; the link rule keeps |ξ| ≤ 1.5 max(Δx): ask slightly wider.
  const double reach = kLinkFactor * widest * (1.0 + 1e-9);
  std::vector<std::int32_t> near;
  std::vector<std::vector<std::pair<std::int32_t, double>>> links(g.size());
  for (std::size_t n = 0; n < g.size(); ++n) {
    search.within(n, reach, near);
    for (const auto m : near) {
      const double d = link_length(p, g.particle[n], g.particle[m]);
      if (d >= 0.0) links[n].emplace_back(m, d);
    }
  }
  write_csr(g, links.data());
  return g;
}

const DamageGraph& GrowingDamageGraph::update(const ParticleStore& p, const Revision& revision,
                                              const double* damage) {
  const double* phi = damage ? damage : p.damage.data();
  if (revision != revision_ || p.size() != size_ || !members_still_damaged(phi))
    restart(p, revision);
  const std::size_t before = members_.size();
  // The members are still damaged: as many damaged particles as members means none joined (a
  // count the compiler vectorises, against a scan that checks membership particle by particle).
  std::size_t damaged = 0;
  for (std::size_t i = 0; i < p.size(); ++i) damaged += phi[i] >= threshold_ ? 1 : 0;
  if (damaged != before)
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!member_[i] && phi[i] >= threshold_) join(p, static_cast<std::int32_t>(i));
  if (members_.size() != before || graph_.offset.empty()) {
    std::inplace_merge(members_.begin(), members_.begin() + static_cast<std::ptrdiff_t>(before),
                       members_.end());
    write_graph(p.size());
  }
  return graph_;
}

void GrowingDamageGraph::restart(const ParticleStore& p, const Revision& revision) {
  ++version_;
  revision_ = revision;
  size_ = p.size();
  double widest = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) widest = std::max(widest, p.spacing[i]);
  // Cells at least as wide as the longest link: a link joins particles of adjacent cells.
  cell_ = kLinkFactor * widest * (1.0 + 1e-9);
  members_.clear();
  member_.assign(p.size(), 0);
  links_.clear();
  cells_.clear();
  graph_ = DamageGraph{};
}

bool GrowingDamageGraph::members_still_damaged(const double* damage) const {
  return std::all_of(members_.begin(), members_.end(),
                     [&](std::int32_t i) { return damage[i] >= threshold_; });
}

std::uint64_t GrowingDamageGraph::cell_key(const ParticleStore& p, std::size_t i,
                                           const std::int64_t shift[3]) const {
  std::uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const auto c =
        a < p.dim()
            ? static_cast<std::int64_t>(std::floor(p.reference_position[a][i] / cell_)) + shift[a]
            : 0;
    key = (key << 21) | (static_cast<std::uint64_t>(c + (std::int64_t{1} << 20)) & 0x1fffff);
  }
  return key;
}

void GrowingDamageGraph::join(const ParticleStore& p, std::int32_t i) {
  const int reach[3] = {1, p.dim() > 1 ? 1 : 0, p.dim() > 2 ? 1 : 0};
  std::int64_t shift[3];
  for (shift[0] = -reach[0]; shift[0] <= reach[0]; ++shift[0])
    for (shift[1] = -reach[1]; shift[1] <= reach[1]; ++shift[1])
      for (shift[2] = -reach[2]; shift[2] <= reach[2]; ++shift[2]) {
        const auto cell = cells_.find(cell_key(p, static_cast<std::size_t>(i), shift));
        if (cell == cells_.end()) continue;
        for (const auto j : cell->second) {
          const double d = link_length(p, static_cast<std::size_t>(i), static_cast<std::size_t>(j));
          if (d >= 0.0) links_.push_back({i, j, d});
        }
      }
  const std::int64_t here[3] = {0, 0, 0};
  cells_[cell_key(p, static_cast<std::size_t>(i), here)].push_back(i);
  member_[i] = 1;
  members_.push_back(i);
}

void GrowingDamageGraph::write_graph(std::size_t n) {
  ++version_;
  node_of_.assign(n, -1);
  auto& g = graph_;
  g.particle = members_;
  for (std::size_t k = 0; k < members_.size(); ++k)
    node_of_[members_[k]] = static_cast<std::int32_t>(k);
  // CSR by counting: each link once from each end (|X_a − X_b| and |X_b − X_a| are the same
  // bits, so one length serves both), then each node's links in neighbour order.
  g.offset.assign(members_.size() + 1, 0);
  for (const auto& l : links_) ++g.offset[node_of_[l.a] + 1], ++g.offset[node_of_[l.b] + 1];
  for (std::size_t k = 0; k < members_.size(); ++k) g.offset[k + 1] += g.offset[k];
  fill_.assign(g.offset.begin(), g.offset.end() - 1);
  sorted_.resize(2 * links_.size());
  for (const auto& l : links_) {
    const auto a = node_of_[l.a], b = node_of_[l.b];
    sorted_[fill_[a]++] = {b, l.length};
    sorted_[fill_[b]++] = {a, l.length};
  }
  g.neighbor.resize(sorted_.size());
  g.length.resize(sorted_.size());
  for (std::size_t k = 0; k < members_.size(); ++k) {
    const auto first = sorted_.begin() + static_cast<std::ptrdiff_t>(g.offset[k]);
    std::sort(first, sorted_.begin() + static_cast<std::ptrdiff_t>(g.offset[k + 1]));
  }
  for (std::size_t e = 0; e < sorted_.size(); ++e)
    g.neighbor[e] = sorted_[e].first, g.length[e] = sorted_[e].second;
}

}  // namespace dhpd::measure
