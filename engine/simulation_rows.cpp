// The incremental rebuild of a refinement event (dhpd.md §1, §8; IJNME 2016 §5.3): only the
// children and the owners of bonds on the parents (or within reach of a child) get new bond
// rows; the dual rows of their neighbours are patched; no-healing decides the new bonds' states.
#include <algorithm>
#include <cmath>

#include "engine/errors.hpp"
#include "engine/no_healing.hpp"
#include "engine/refinement_scratch.hpp"

namespace dhpd {

namespace {
void sort_unique(std::vector<std::int32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}
}  // namespace

void Simulation::ensure_grid() {
  if (grid_) return;
  double base = 0.0;
  for (std::size_t i = 0; i < p_.size(); ++i) base = std::max(base, p_.spacing[i]);
  grid_.emplace(p_.dim(), base, setup_.horizon_factor);
  for (std::size_t i = 0; i < p_.size(); ++i)
    grid_->insert(static_cast<std::int32_t>(i), point_of(p_.reference_position, i), p_.spacing[i]);
}

std::vector<std::int32_t> Simulation::old_neighbourhood(const SplitPlan& plan) const {
  // An old bond crossing a new segment has its owner within one bond length of the segment, and
  // every new segment lies within a horizon (plus a cell) of its child's parent.
  std::vector<std::int32_t> near, found;
  if (broken_ == 0 || p_.dim() == 1) return near;
  const double bond_reach = (max_horizon_ + reach_) * (1.0 + 1e-9);
  for (const auto q : plan.parents) {
    const auto u = static_cast<std::size_t>(q);
    grid_->within(point_of(p_.reference_position, u), 2.0 * bond_reach + p_.spacing[u], found);
    near.insert(near.end(), found.begin(), found.end());
    near.push_back(q);
  }
  sort_unique(near);
  return near;
}

std::vector<std::int32_t> Simulation::event_energy_rows(const SplitPlan& plan) const {
  // Rows whose energy an event can change: the parents' and their neighbours' (owners of bonds on
  // a parent lie within a horizon of it), and those reaching a child (within a cell of its parent).
  std::vector<std::int32_t> rows, found;
  // With the interface correction the factors of bonds between touched rows change too: their
  // owners lie up to one more bond length out.
  const double widest =
      (corrects_interfaces() ? 2.0 : 1.0) * (max_horizon_ + reach_) * (1.0 + 1e-9);
  for (const auto q : plan.parents) {
    const auto u = static_cast<std::size_t>(q);
    grid_->within(point_of(p_.reference_position, u), widest + 2.0 * p_.spacing[u], found);
    rows.insert(rows.end(), found.begin(), found.end());
    rows.push_back(q);
  }
  sort_unique(rows);
  return rows;
}

std::vector<std::int32_t> Simulation::owners_to_rebuild(const SplitPlan& plan) const {
  std::vector<std::int32_t> owners(plan.child_slot), found;
  for (const auto q : plan.parents)  // owners of bonds on the parents (their dual rows)
    for (auto d = dual_.begin(static_cast<std::size_t>(q));
         d < dual_.end(static_cast<std::size_t>(q)); ++d)
      owners.push_back(bonds_.owner[dual_.bond[d]]);
  const BondRowBuilder builder(p_, setup_.partial_volume, setup_.cracks, reach_);
  const double widest = (max_horizon_ + reach_) * (1.0 + 1e-9);
  const auto& X = p_.reference_position;
  for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
    const auto& xc = plan.child_position[c];
    grid_->within(xc, widest, found);
    for (const auto k : found) {  // unsplit particles whose horizon reaches the child
      if (child_of_slot_[static_cast<std::size_t>(k)] >= 0) continue;
      double d2 = 0.0;
      for (int a = 0; a < p_.dim(); ++a) d2 += (X[a][k] - xc[a]) * (X[a][k] - xc[a]);
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
}  // namespace

void Simulation::rebuild_rows(EventScratch& ev, RefinementEvent& out) {
  const auto& plan = ev.plan;
  const BondRowBuilder builder(p_, setup_.partial_volume, setup_.cracks, reach_);
  const OldGeneration old{bonds_, p_, &ev.parents, &parent_slot_};
  const OldSegments segments(old, ev.near);
  const bool rule = broken_ > 0;
  const bool fracture = setup_.effects.fracture;
  auto previous = [&](std::int32_t x) {
    const auto c = child_of_slot_[static_cast<std::size_t>(x)];
    return c < 0 ? x : plan.parents[static_cast<std::size_t>(plan.child_parent[c])];
  };
  // Phase 1: the new rows, decided against the previous generation (nothing committed yet).
  NewRows rows;
  std::vector<std::int32_t> cand;
  const auto& X = p_.reference_position;
  for (const auto i : ev.owners) {
    const auto u = static_cast<std::size_t>(i);
    grid_->within(point_of(X, u), builder.search_radius(u), cand, i);
    builder.keep_bonds(u, cand, &rows.length, &rows.weight);
    for (const auto j : cand) {
      const auto v = static_cast<std::size_t>(j);
      const bool unsplit = child_of_slot_[u] < 0 && child_of_slot_[v] < 0;
      const bool cut =
          rule && starts_broken(old, segments, point_of(X, u), point_of(X, v), previous(i),
                                previous(j), unsplit, 0.5 * std::min(p_.spacing[u], p_.spacing[v]));
      const bool over = !cut && fracture &&
                        starts_overstretched(p_, u, v, rows.length[rows.neighbor.size()], s0_[u]);
      rows.neighbor.push_back(j);
      rows.intact.push_back(cut || over ? 0 : 1);
      out.started_broken += cut ? 1 : 0;
      out.started_overstretched += over ? 1 : 0;
    }
    rows.start.push_back(static_cast<std::int64_t>(rows.neighbor.size()));
  }
  // Phase 2: retire the old rows (parents' rows included: their slots are children now).
  ev.dirty = ev.owners;  // owners, and every particle whose dual row changes
  for (const auto i : ev.owners) {
    const auto u = static_cast<std::size_t>(i);
    for (auto b = bonds_.begin(u); b < bonds_.end(u); ++b) {
      dual_.remove(static_cast<std::size_t>(bonds_.neighbor[b]), static_cast<BondId>(b));
      ev.dirty.push_back(bonds_.neighbor[b]);
      broken_ -= bonds_.intact[b] ? 0 : 1;
      bonds_.owner[b] = bonds_.neighbor[b] = -1;
      bonds_.intact[b] = 0;
    }
    bonds_.live -= bonds_.rows.count[u];
    bonds_.rows.count[u] = 0;
  }
  // Phase 3: write the new rows and add them to their neighbours' dual rows.
  for (std::size_t k = 0; k < ev.owners.size(); ++k) {
    const auto u = static_cast<std::size_t>(ev.owners[k]);
    const auto n = static_cast<std::int32_t>(rows.start[k + 1] - rows.start[k]);
    const auto s = bonds_.rows.make_room(u, n);
    bonds_.fit_arena();
    if (bonds_.slots() > static_cast<std::size_t>(INT32_MAX))
      throw EngineError("more than 2^31 bond slots: not supported by 32-bit bond ids");
    for (std::int32_t e = 0; e < n; ++e) {
      const auto r = static_cast<std::size_t>(rows.start[k] + e);
      const auto b = static_cast<std::size_t>(s + e);
      bonds_.owner[b] = ev.owners[k];
      bonds_.neighbor[b] = rows.neighbor[r];
      bonds_.length[b] = rows.length[r];
      bonds_.weight[b] = rows.weight[r];
      bonds_.stiffness[b] = 1.0;  // set by the interface correction (finish_event)
      bonds_.intact[b] = rows.intact[r];
      broken_ += rows.intact[r] ? 0 : 1;
      dual_.add(static_cast<std::size_t>(rows.neighbor[r]), static_cast<BondId>(b));
      ev.dirty.push_back(rows.neighbor[r]);
    }
    bonds_.rows.count[u] = n;
    bonds_.live += n;
    out.bonds_rebuilt += static_cast<std::size_t>(n);
  }
  sort_unique(ev.dirty);
  out.rows_rebuilt = ev.owners.size();
}

}  // namespace dhpd
