// Parent selection for refinement events: buffer, grading, level limit (docs/theory.md §13.2).
#include "refine/refiner.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>

#include "engine/discretization/neighbor_search.hpp"

namespace dhpd::refine {

namespace {
/// The particles j ≠ i within `radius` of particle i (reference positions), from the refiner's
/// grid when it has one, else from a k-d tree built on first use (the same predicate).
class Neighbours {
 public:
  Neighbours(const ParticleStore& p, const SpatialGrid* grid) : p_(p), grid_(grid) {}
  void within(std::size_t i, double radius, std::vector<std::int32_t>& out) {
    if (grid_) {
      out.clear();
      grid_->within(point_of(p_.reference_position, i), radius, out, static_cast<std::int32_t>(i));
      return;
    }
    if (!tree_) tree_ = std::make_unique<NeighborSearch>(p_.reference_position, p_.dim());
    tree_->within(i, radius, out);
  }

 private:
  const ParticleStore& p_;
  const SpatialGrid* grid_;
  std::unique_ptr<NeighborSearch> tree_;
};
}  // namespace

void add_buffer(const ParticleStore& p, double buffer, std::vector<std::uint8_t>& marked,
                const SpatialGrid* grid, const std::vector<std::uint8_t>* skip) {
  if (buffer <= 0.0 || std::find(marked.begin(), marked.end(), 1) == marked.end()) return;
  Neighbours search(p, grid);
  const auto seeds = marked;
  std::vector<std::int32_t> near;
  for (std::size_t t = 0; t < p.size(); ++t) {
    if (!seeds[t] || (skip && (*skip)[t])) continue;
    search.within(t, buffer * p.horizon[t], near);
    for (const auto j : near) marked[static_cast<std::size_t>(j)] = 1;
  }
}

void keep_within(const ParticleStore& p, const std::vector<geometry::Shape>& within,
                 std::vector<std::uint8_t>& marked) {
  if (within.empty()) return;
  for (std::size_t i = 0; i < marked.size(); ++i) {
    if (!marked[i]) continue;
    const auto x = point_of(p.reference_position, i);
    marked[i] = std::any_of(within.begin(), within.end(),
                            [&](const geometry::Shape& w) { return w.contains(x, p.dim()); });
  }
}

std::vector<std::int32_t> graded_parents(const Simulation& sim, std::vector<std::uint8_t> marked,
                                         int max_level, const SpatialGrid* grid) {
  const auto& p = sim.particles();
  const auto& level = p.level;
  std::vector<std::int32_t> work;
  for (std::size_t i = 0; i < marked.size(); ++i) {
    if (marked[i] && level[i] >= max_level) marked[i] = 0;
    if (marked[i]) work.push_back(static_cast<std::int32_t>(i));
  }
  if (work.empty()) return {};
  // Bonds after the split reach at most max(δ_i, δ_q) + one parent spacing (children offsets and
  // radii): every q that close is a neighbour of i's children.
  Neighbours search(p, grid);
  const double max_horizon = *std::max_element(p.horizon.begin(), p.horizon.end());
  std::vector<std::int32_t> near;
  while (!work.empty()) {
    const auto i = static_cast<std::size_t>(work.back());
    work.pop_back();
    search.within(i, max_horizon + p.spacing[i], near);
    for (const auto qi : near) {
      const auto q = static_cast<std::size_t>(qi);
      // The children of i sit at level[i] + 1: a neighbour at level[i] − 1 or below must split.
      if (marked[q] || level[q] >= level[i]) continue;
      double d2 = 0.0;
      for (int a = 0; a < p.dim(); ++a)
        d2 += std::pow(p.reference_position[a][q] - p.reference_position[a][i], 2);
      if (std::sqrt(d2) > std::max(p.horizon[i], p.horizon[q]) + p.spacing[i]) continue;
      marked[q] = 1;
      work.push_back(qi);
    }
  }
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < marked.size(); ++i)
    if (marked[i]) out.push_back(static_cast<std::int32_t>(i));
  return out;
}

std::vector<RefinementEvent> Refiner::refine_zones(Simulation& sim) {
  std::vector<RefinementEvent> events;
  for (int pass = 0; pass < s_.max_level && !s_.zones.empty(); ++pass) {
    const auto& p = sim.particles();
    std::vector<std::uint8_t> marked(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const geometry::Vec3 x{p.reference_position[0][i], p.reference_position[1][i],
                             p.reference_position[2][i]};
      for (const auto& z : s_.zones)
        if (z.contains(x, p.dim())) marked[i] = 1;
    }
    const auto parents = graded_parents(sim, std::move(marked), s_.max_level, &search_.grid(sim));
    if (parents.empty()) break;
    if (event_check_) event_check_(sim, parents.size());
    events.push_back(split(sim, parents, s_.mapping, &search_, cancelled_));
  }
  settled_.clear();
  return events;
}

bool Refiner::settled_current(const Simulation& sim) const {
  return settled_sim_ == &sim && settled_generation_ == sim.generation() &&
         settled_particles_ == sim.particles().size();
}

void Refiner::mark_settled_current(const Simulation& sim) {
  settled_sim_ = &sim;
  settled_generation_ = sim.generation();
  settled_particles_ = sim.particles().size();
}

std::uint64_t Refiner::watch_key() const {
  // The limits depend on the threshold and max_level alone (stretch_limits): refiners that share
  // them share the watch.
  return std::bit_cast<std::uint64_t>(*s_.trigger.stretch) ^
         (static_cast<std::uint64_t>(s_.max_level) << 56);
}

const std::vector<std::uint8_t>* Refiner::stretch_hits(const Simulation& sim) const {
  return s_.trigger.stretch ? sim.stretch_watch_hits(watch_key()) : nullptr;
}

void Refiner::watch_stretch(Simulation& sim) const {
  // Set once per discretisation (the stepper drops it at every change): the steps from here on
  // flag what the next checks would find (docs/theory.md §13.1).
  if (s_.trigger.stretch && !sim.watching_stretch(watch_key()))
    sim.watch_stretch(stretch_limits(sim, *s_.trigger.stretch, s_.max_level), watch_key());
}

RefinementEvent Refiner::check(Simulation& sim) {
  const SpatialGrid& grid = search_.grid(sim);  // current: rebuilt only after a change
  if (!settled_current(sim)) settled_.clear();
  mark_settled_current(sim);
  const auto& settled = settled_.update(sim.particles(), grid);
  auto marked = triggered(sim, s_.trigger, {s_.max_level, &settled, stretch_hits(sim)});
  add_buffer(sim.particles(), s_.buffer, marked, &grid, &settled);
  keep_within(sim.particles(), s_.within, marked);
  const auto parents = graded_parents(sim, std::move(marked), s_.max_level, &grid);
  if (parents.empty()) {
    watch_stretch(sim);
    RefinementEvent none;
    none.generation = sim.generation();
    return none;
  }
  if (event_check_) event_check_(sim, parents.size());
  const auto& ids = sim.particles().id;
  const std::int32_t first_new_id = *std::max_element(ids.begin(), ids.end()) + 1;
  auto event = split(sim, parents, s_.mapping, &search_, cancelled_);
  settled_.after_event(sim.particles(), search_.grid(sim), first_new_id);
  mark_settled_current(sim);  // the event's own change: the memo followed it
  watch_stretch(sim);
  return event;
}

}  // namespace dhpd::refine
