// The incremental rebuild of a refinement event (docs/theory.md §2, §13.6; IJNME 2016 §5.3): only
// the children and the owners of bonds on the parents (or within reach of a child) get new own
// bonds; their neighbours' rows get the dual side; no-healing decides the new bonds' states.
#include "refine/rebuild.hpp"

#include <algorithm>
#include <array>
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

/// Calls f(k, scratch, found) for k in [0, n) in parallel, in chunks between which the event may
/// be cancelled; what each thread appends to its `found` joins `*out` when given (callers sort
/// it, so the order does not matter).
template <class F>
void each_in_chunks(std::size_t n, const CancelCheck& cancelled, const char* what,
                    std::vector<std::int32_t>* out, F&& f) {
  constexpr std::size_t kChunk = 256;
  for (std::size_t begin = 0; begin < n; begin += kChunk) {
    if (cancelled && cancelled())
      throw EventCancelled(std::string("refinement event cancelled while ") + what);
    const auto end = static_cast<std::int64_t>(std::min(n, begin + kChunk));
#pragma omp parallel if (end - static_cast <std::int64_t>(begin) >= 32)
    {
      std::vector<std::int32_t> scratch, found;
#pragma omp for schedule(dynamic, 8) nowait
      for (auto k = static_cast<std::int64_t>(begin); k < end; ++k)
        f(static_cast<std::size_t>(k), scratch, found);
      if (out) {
#pragma omp critical(dhpd_rebuild_join)
        out->insert(out->end(), found.begin(), found.end());
      }
    }
  }
}

/// Every particle within `radius(q)` of a parent q, and the parents, ascending.
template <class Radius>
std::vector<std::int32_t> around_parents(const Simulation& sim, const SpatialGrid& grid,
                                         const SplitPlan& plan, Radius radius,
                                         const CancelCheck& cancelled) {
  const auto& p = sim.particles();
  std::vector<std::int32_t> out;
  each_in_chunks(
      plan.parents.size(), cancelled, "searching around the parents", &out,
      [&](std::size_t k, std::vector<std::int32_t>& found, std::vector<std::int32_t>& to) {
        const auto q = plan.parents[k];
        const auto u = static_cast<std::size_t>(q);
        grid.within(point_of(p.reference_position, u), radius(u), found);
        to.insert(to.end(), found.begin(), found.end());
        to.push_back(q);
      });
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
  // Rows whose energy an event can change: every row with an entry that changes (the rows of
  // owners rebuilt, which lie within a bond length and a cell of a parent, and the rows of their
  // neighbours, one bond length further, which hold the dual side; the interface correction
  // changes only bonds between such rows).
  const double widest = 2.0 * widest_bond(sim);
  return around_parents(
      sim, grid, plan, [&](std::size_t u) { return widest + 2.0 * sim.particles().spacing[u]; },
      cancelled);
}

std::vector<std::int32_t> owners_to_rebuild(const Simulation& sim, const SpatialGrid& grid,
                                            const EventScratch& ev, const CancelCheck& cancelled) {
  const auto& plan = ev.plan;
  const auto& p = sim.particles();
  const auto& bonds = sim.bonds();
  std::vector<std::int32_t> owners(plan.child_slot);
  for (const auto q : plan.parents) {  // owners of bonds on the parents (the dual side of q's row)
    const auto u = static_cast<std::size_t>(q);
    for (auto k = bonds.begin(u); k < bonds.end(u); ++k)
      if (bonds.has_dual(k)) owners.push_back(bonds.other[k]);
  }
  const BondRowBuilder builder(p, sim.setup().partial_volume, sim.setup().cracks, sim.bond_reach());
  const double widest = widest_bond(sim);
  const auto& X = p.reference_position;
  each_in_chunks(
      plan.child_slot.size(), cancelled, "finding the rows to rebuild", &owners,
      [&](std::size_t c, std::vector<std::int32_t>& found, std::vector<std::int32_t>& to) {
        const auto& xc = plan.child_position[c];
        grid.within(xc, widest, found);
        for (const auto k : found) {  // unsplit particles whose horizon reaches c
          if ((*ev.child_of_slot)[static_cast<std::size_t>(k)] >= 0) continue;
          double d2 = 0.0;
          for (int a = 0; a < p.dim(); ++a) d2 += (X[a][k] - xc[a]) * (X[a][k] - xc[a]);
          const double r = builder.search_radius(static_cast<std::size_t>(k));
          if (d2 < r * r) to.push_back(k);
        }
      });
  sort_unique(owners);
  return owners;
}

namespace {
/// Phase 1: the owners' new own bonds, decided against the previous generation (nothing
/// committed yet). Each row is decided on its own (in parallel, in chunks between which the
/// event may be cancelled); the counts are summed in row order.
std::vector<std::vector<NewBond>> decide_rows(const Simulation& sim, const SpatialGrid& grid,
                                              const EventScratch& ev, RefinementEvent& out,
                                              const CancelCheck& cancelled) {
  const auto& p = sim.particles();
  const auto& plan = ev.plan;
  const auto& child_of_slot = *ev.child_of_slot;
  const BondRowBuilder builder(p, sim.setup().partial_volume, sim.setup().cracks, sim.bond_reach());
  const OldGeneration old{sim.bonds(), p, &ev.parents, ev.parent_slot};
  const OldSegments segments(old, ev.near);
  const bool rule = sim.broken_bonds() > 0;
  // A static run relaxes the mapped state before any bond breaks (docs/theory.md §22, refinement
  // between relaxations): a child bond the mapping overstretches is left to the relaxation, which
  // decides whether it breaks.
  const bool fracture = sim.setup().effects.fracture && !sim.is_static();
  const auto& s0 = sim.critical_stretch();
  auto previous = [&](std::int32_t x) {
    const auto c = child_of_slot[static_cast<std::size_t>(x)];
    return c < 0 ? x : plan.parents[static_cast<std::size_t>(plan.child_parent[c])];
  };
  std::vector<std::vector<NewBond>> rows(ev.owners.size());
  std::vector<std::array<std::size_t, 2>> started(ev.owners.size(), {0, 0});
  const auto& X = p.reference_position;
  auto decide = [&](std::size_t r, std::vector<std::int32_t>& cand, std::vector<std::int32_t>&) {
    const auto i = ev.owners[r];
    const auto u = static_cast<std::size_t>(i);
    grid.within(point_of(X, u), builder.search_radius(u), cand, i);
    builder.keep_bonds(u, cand);
    for (const auto j : cand) {
      const auto v = static_cast<std::size_t>(j);
      const bool unsplit = child_of_slot[u] < 0 && child_of_slot[v] < 0;
      const bool cut =
          rule && starts_broken(old, segments, point_of(X, u), point_of(X, v), previous(i),
                                previous(j), unsplit, 0.5 * std::min(p.spacing[u], p.spacing[v]));
      const bool over = !cut && fracture &&
                        starts_overstretched(p, u, v, inverse_reference_length(p, u, v), s0[u]);
      rows[r].push_back({j, !(cut || over)});
      started[r][0] += cut ? 1 : 0;
      started[r][1] += over ? 1 : 0;
    }
  };
  each_in_chunks(ev.owners.size(), cancelled, "deciding the new rows", nullptr, decide);
  for (const auto& s : started) out.started_broken += s[0], out.started_overstretched += s[1];
  return rows;
}

/// Broken own bonds of the given rows.
std::int64_t broken_own_bonds(const BondRows& b, const std::vector<std::int32_t>& rows) {
  std::int64_t n = 0;
  for (const auto i : rows)
    for_each_own_bond(b, static_cast<std::size_t>(i),
                      [&](std::int64_t k, std::size_t) { n += b.own_intact(k) ? 0 : 1; });
  return n;
}
}  // namespace

void rebuild_rows(const Simulation& sim, Simulation::Discretisation d, const SpatialGrid& grid,
                  EventScratch& ev, RefinementEvent& out, const CancelCheck& cancelled) {
  const auto rows = decide_rows(sim, grid, ev, out, cancelled);
  // Phase 2: the owners' old bonds (the parents' rows included: their slots are children now)
  // give way to the new ones, own side and dual side.
  ev.broken_change = -broken_own_bonds(d.bonds, ev.owners);
  ev.dirty = replace_own_bonds(d.bonds, d.particles, ev.owners, rows);
  ev.broken_change += broken_own_bonds(d.bonds, ev.owners);
  for (const auto& r : rows) out.bonds_rebuilt += r.size();
  out.rows_rebuilt = ev.owners.size();
}

}  // namespace dhpd::refine
