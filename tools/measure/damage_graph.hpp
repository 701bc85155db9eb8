// The damaged particles of a crack measurement as a graph (IJNME 2016 §5; docs/theory.md §15):
// built at once (damage_graph) or kept between measurements as particles join it
// (GrowingDamageGraph). Both give the same graph: nodes in slot order, each node's links in node
// order.
#pragma once
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd::measure {

/// The damaged set of one measurement as a graph: i, j linked when
/// |X_i − X_j| ≤ 1.5 · max(Δx_i, Δx_j). Local indices; `particle` maps them to store slots.
struct DamageGraph {
  std::vector<std::int32_t> particle;  ///< ascending slots
  std::vector<std::size_t> offset;     ///< CSR: links of node n are [offset[n], offset[n+1])
  std::vector<std::int32_t> neighbor;  ///< ascending within a node
  std::vector<double> length;
  std::size_t size() const { return particle.size(); }
};

/// The particles with φ ≥ threshold and their links, from a neighbour search over all of them.
DamageGraph damage_graph(const ParticleStore& p, double threshold);

/// Which discretisation a store holds: a measurement keeps its graph while both stay the same
/// (Simulation::generation() and layout_version()).
struct Revision {
  std::int64_t generation = -1, layout = -1;
  bool operator==(const Revision&) const = default;
};

/// damage_graph kept between measurements. Damage only grows while the discretisation stays, so a
/// particle that reaches the threshold joins once and its links to the members are found then,
/// from a hash grid of cells 1.5 × the store's largest spacing wide: a measurement costs a scan
/// of φ and the links of the particles that joined. A new revision, a different store size or a
/// member whose φ fell (the state went back) starts the graph again.
class GrowingDamageGraph {
 public:
  explicit GrowingDamageGraph(double threshold) : threshold_(threshold) {}
  /// The graph of `p` now: the same nodes, links and lengths as damage_graph(p, threshold).
  /// `damage`: the particles' damage when not p.damage (a copy taken earlier, one per particle).
  const DamageGraph& update(const ParticleStore& p, const Revision& revision,
                            const double* damage = nullptr);
  /// Changes whenever the graph update() returns changes (anything derived from one graph holds
  /// while it stays).
  std::uint64_t version() const { return version_; }

 private:
  struct Link {
    std::int32_t a, b;  ///< slots
    double length;
  };
  void restart(const ParticleStore& p, const Revision& revision);
  bool members_still_damaged(const double* damage) const;
  std::uint64_t cell_key(const ParticleStore& p, std::size_t i, const std::int64_t shift[3]) const;
  void join(const ParticleStore& p, std::int32_t i);
  void write_graph(std::size_t n);

  double threshold_;
  std::uint64_t version_ = 0;
  Revision revision_{};
  std::size_t size_ = 0;
  double cell_ = 0.0;
  std::vector<std::int32_t> members_;  ///< ascending slots
  std::vector<std::uint8_t> member_;   ///< per slot
  std::vector<Link> links_;            ///< each pair once
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> cells_;
  DamageGraph graph_;
  std::vector<std::int32_t> node_of_;                    ///< write_graph scratch, per slot
  std::vector<std::size_t> fill_;                        ///< write_graph scratch, per node
  std::vector<std::pair<std::int32_t, double>> sorted_;  ///< write_graph scratch, per link end
};

}  // namespace dhpd::measure
