// The incremental rebuild of a refinement event (docs/theory.md §2, §13.6; IJNME 2016 §5.3): only
// the children and the owners of bonds on the parents (or within reach of a child) get new bond
// rows; the dual rows of their neighbours are patched; no-healing decides the new bonds' states.
#include "refine/rebuild.hpp"

#include <algorithm>
#include <cmath>

#include "engine/base/errors.hpp"
#include "refine/no_healing.hpp"

namespace dhpd::refine {

namespace {
void sort_unique(std::vector<std::int32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// The widest a bond reaches (upper bound of every horizon plus radius), with round-off slack.
double widest_bond(const Simulation& sim) {
  return (sim.max_horizon() + sim.bond_reach()) * (1.0 + 1e-9);
}

/// Every particle within `radius(q)` of a parent q, and the parents, ascending.
template <class Radius>
std::vector<std::int32_t> around_parents(const Simulation& sim, const SpatialGrid& grid,
                                         const SplitPlan& plan, Radius radius,
                                         const CancelCheck& cancelled) {
  const auto& p = sim.particles();
  std::vector<std::int32_t> out, found;
  CancelPoll poll(cancelled);
  for (const auto q : plan.parents) {
    poll("searching around the parents");
    const auto u = static_cast<std::size_t>(q);
    grid.within(point_of(p.reference_position, u), radius(u), found);
    out.insert(out.end(), found.begin(), found.end());
    out.push_back(q);
  }
  sort_unique(out);
  return out;
}
}  // namespace

std::vector<std::int32_t> old_neighbourhood(const Simulation& sim, const SpatialGrid& grid,
                                            const SplitPlan& plan, const CancelCheck& cancelled) {
  // An old bond crossing a new segment has its owner within one bond length of the segment, and
  // every new segment lies within a horizon (plus a cell) of its child's parent.
  if (sim.broken_bonds() == 0 || sim.particles().dim() == 1) return {};
  const double reach = widest_bond(sim);
  return around_parents(
      sim, grid, plan, [&](std::size_t u) { return 2.0 * reach + sim.particles().spacing[u]; },
      cancelled);
}

std::vector<std::int32_t> event_energy_rows(const Simulation& sim, const SpatialGrid& grid,
                                            const SplitPlan& plan, const CancelCheck& cancelled) {
  // Rows whose energy an event can change: the parents' and their neighbours' (owners of bonds on
  // a parent lie within a horizon of it), and those reaching a child (within a cell of its parent).
  // With the interface correction the factors of bonds between touched rows change too: their
  // owners lie up to one more bond length out.
  const double widest = (sim.corrects_interfaces() ? 2.0 : 1.0) * widest_bond(sim);
  return around_parents(
      sim, grid, plan, [&](std::size_t u) { return widest + 2.0 * sim.particles().spacing[u]; },
      cancelled);
}

std::vector<std::int32_t> owners_to_rebuild(const Simulation& sim, const SpatialGrid& grid,
                                            const EventScratch& ev, const CancelCheck& cancelled) {
  const auto& plan = ev.plan;
  const auto& p = sim.particles();
  const auto& bonds = sim.bonds();
  const auto& dual = sim.dual();
  std::vector<std::int32_t> owners(plan.child_slot), found;
  for (const auto q : plan.parents)  // owners of bonds on the parents (their dual rows)
    for (auto d = dual.begin(static_cast<std::size_t>(q));
         d < dual.end(static_cast<std::size_t>(q)); ++d)
      owners.push_back(bonds.owner[dual.bond[d]]);
  const BondRowBuilder builder(p, sim.setup().partial_volume, sim.setup().cracks, sim.bond_reach());
  const double widest = widest_bond(sim);
  const auto& X = p.reference_position;
  CancelPoll poll(cancelled);
  for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
    poll("finding the rows to rebuild");
    const auto& xc = plan.child_position[c];
    grid.within(xc, widest, found);
    for (const auto k : found) {  // unsplit particles whose horizon reaches the child
      if ((*ev.child_of_slot)[static_cast<std::size_t>(k)] >= 0) continue;
      double d2 = 0.0;
      for (int a = 0; a < p.dim(); ++a) d2 += (X[a][k] - xc[a]) * (X[a][k] - xc[a]);
      const double r = builder.search_radius(static_cast<std::size_t>(k));
      if (d2 < r * r) owners.push_back(k);
    }
  }
  sort_unique(owners);
  return owners;
}

namespace {
/// The new rows of the owners, flat: row k is [start[k], start[k+1]).
struct NewRows {
  std::vector<std::int64_t> start{0};
  std::vector<std::int32_t> neighbor;
  std::vector<double> length, weight;
  std::vector<std::uint8_t> intact;
};

/// Phase 1: the new rows, decided against the previous generation (nothing committed yet).
NewRows decide_rows(const Simulation& sim, const SpatialGrid& grid, const EventScratch& ev,
                    RefinementEvent& out, const CancelCheck& cancelled) {
  const auto& p = sim.particles();
  const auto& plan = ev.plan;
  const auto& child_of_slot = *ev.child_of_slot;
  const BondRowBuilder builder(p, sim.setup().partial_volume, sim.setup().cracks, sim.bond_reach());
  const OldGeneration old{sim.bonds(), p, &ev.parents, ev.parent_slot};
  const OldSegments segments(old, ev.near);
  const bool rule = sim.broken_bonds() > 0;
  const bool fracture = sim.setup().effects.fracture;
  const auto& s0 = sim.critical_stretch();
  auto previous = [&](std::int32_t x) {
    const auto c = child_of_slot[static_cast<std::size_t>(x)];
    return c < 0 ? x : plan.parents[static_cast<std::size_t>(plan.child_parent[c])];
  };
  NewRows rows;
  std::vector<std::int32_t> cand;
  const auto& X = p.reference_position;
  CancelPoll poll(cancelled);
  for (const auto i : ev.owners) {
    poll("deciding the new rows");
    const auto u = static_cast<std::size_t>(i);
    grid.within(point_of(X, u), builder.search_radius(u), cand, i);
    builder.keep_bonds(u, cand, &rows.length, &rows.weight);
    for (const auto j : cand) {
      const auto v = static_cast<std::size_t>(j);
      const bool unsplit = child_of_slot[u] < 0 && child_of_slot[v] < 0;
      const bool cut =
          rule && starts_broken(old, segments, point_of(X, u), point_of(X, v), previous(i),
                                previous(j), unsplit, 0.5 * std::min(p.spacing[u], p.spacing[v]));
      const bool over = !cut && fracture &&
                        starts_overstretched(p, u, v, rows.length[rows.neighbor.size()], s0[u]);
      rows.neighbor.push_back(j);
      rows.intact.push_back(cut || over ? 0 : 1);
      out.started_broken += cut ? 1 : 0;
      out.started_overstretched += over ? 1 : 0;
    }
    rows.start.push_back(static_cast<std::int64_t>(rows.neighbor.size()));
  }
  return rows;
}
}  // namespace

void rebuild_rows(const Simulation& sim, Simulation::Discretisation d, const SpatialGrid& grid,
                  EventScratch& ev, RefinementEvent& out, const CancelCheck& cancelled) {
  const NewRows rows = decide_rows(sim, grid, ev, out, cancelled);
  auto& bonds = d.bonds;
  auto& dual = d.dual;
  // Phase 2: retire the old rows (parents' rows included: their slots are children now).
  ev.dirty = ev.owners;  // owners, and every particle whose dual row changes
  for (const auto i : ev.owners) {
    const auto u = static_cast<std::size_t>(i);
    for (auto b = bonds.begin(u); b < bonds.end(u); ++b) {
      dual.remove(static_cast<std::size_t>(bonds.neighbor[b]), static_cast<BondId>(b));
      ev.dirty.push_back(bonds.neighbor[b]);
      ev.broken_change -= bonds.intact[b] ? 0 : 1;
      bonds.owner[b] = bonds.neighbor[b] = -1;
      bonds.intact[b] = 0;
    }
    bonds.live -= bonds.rows.count[u];
    bonds.rows.count[u] = 0;
  }
  // Phase 3: write the new rows and add them to their neighbours' dual rows.
  for (std::size_t k = 0; k < ev.owners.size(); ++k) {
    const auto u = static_cast<std::size_t>(ev.owners[k]);
    const auto n = static_cast<std::int32_t>(rows.start[k + 1] - rows.start[k]);
    const auto s = bonds.rows.make_room(u, n);
    bonds.fit_arena();
    if (bonds.slots() > static_cast<std::size_t>(INT32_MAX))
      throw EngineError("more than 2^31 bond slots: not supported by 32-bit bond ids");
    for (std::int32_t e = 0; e < n; ++e) {
      const auto r = static_cast<std::size_t>(rows.start[k] + e);
      const auto b = static_cast<std::size_t>(s + e);
      bonds.owner[b] = ev.owners[k];
      bonds.neighbor[b] = rows.neighbor[r];
      bonds.length[b] = rows.length[r];
      bonds.weight[b] = rows.weight[r];
      bonds.stiffness[b] = 1.0;  // set by the interface correction (commit_edit)
      bonds.intact[b] = rows.intact[r];
      ev.broken_change += rows.intact[r] ? 0 : 1;
      dual.add(static_cast<std::size_t>(rows.neighbor[r]), static_cast<BondId>(b));
      ev.dirty.push_back(rows.neighbor[r]);
    }
    bonds.rows.count[u] = n;
    bonds.live += n;
    out.bonds_rebuilt += static_cast<std::size_t>(n);
  }
  sort_unique(ev.dirty);
  out.rows_rebuilt = ev.owners.size();
}

}  // namespace dhpd::refine
