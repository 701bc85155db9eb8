// Interaction rows from bonds and dual bonds (IJNME 2016 eq. 27; CMAME 2017 §3, eq. 5).
#include "engine/physics/interactions.hpp"
#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"

namespace dhpd {

namespace {

std::int32_t row_length(ForceModel model, const BondList& bonds, const DualList& dual,
                        std::size_t i) {
  const auto own = bonds.end(i) - bonds.begin(i);
  const auto duals = model == ForceModel::DualHorizon ? dual.end(i) - dual.begin(i) : 0;
  return static_cast<std::int32_t>(own + duals);
}

/// Fills row i at its start (which has room for it).
void fill_row(InteractionList& il, std::size_t i, ForceModel model, const BondList& bonds,
              const DualList& dual, const ParticleStore& p, const std::vector<double>& C) {
  const bool with_dual = model == ForceModel::DualHorizon;
  // Classical BB-PD: c = 2C on each own bond, no reactions (IJNME 2016 §3.1).
  const double own_factor = with_dual ? 1.0 : 2.0;
  std::int64_t k = il.rows.start[i];
  for (auto b = bonds.begin(i); b < bonds.end(i); ++b, ++k) {
    const auto j = bonds.neighbor[b];
    il.other[k] = j;
    il.inv_length[k] = 1.0 / bonds.length[b];
    il.coefficient[k] = bond_law::coefficient(own_factor, C[i], bonds.weight[b], bonds.stiffness[b],
                                              p.volume[j], bonds.intact[b]);
    il.own_slot[b] = k;
  }
  if (with_dual)
    for (auto d = dual.begin(i); d < dual.end(i); ++d, ++k) {
      const auto b = dual.bond[d];
      const auto owner = bonds.owner[b];
      il.other[k] = owner;
      il.inv_length[k] = 1.0 / bonds.length[b];
      il.coefficient[k] = bond_law::coefficient(1.0, C[owner], bonds.weight[b], bonds.stiffness[b],
                                                p.volume[owner], bonds.intact[b]);
      il.dual_slot[b] = k;
    }
  il.rows.count[i] = static_cast<std::int32_t>(k - il.rows.start[i]);
}

void fit_arena(InteractionList& il) {
  const auto n = static_cast<std::size_t>(il.rows.arena);
  il.other.resize(n, 0);
  il.inv_length.resize(n, 0.0);
  il.coefficient.resize(n, 0.0);
}

}  // namespace

InteractionList build_interactions(ForceModel model, const BondList& bonds, const DualList& dual,
                                   const ParticleStore& p, const std::vector<double>& C) {
  const std::size_t n = bonds.particles();
  std::vector<std::int32_t> counts(n);
  for (std::size_t i = 0; i < n; ++i) counts[i] = row_length(model, bonds, dual, i);
  InteractionList il;
  il.rows = RowIndex::packed(counts);
  il.live = il.rows.arena;
  fit_arena(il);
  il.own_slot.assign(bonds.slots(), -1);
  il.dual_slot.assign(bonds.slots(), -1);
#pragma omp parallel for schedule(static) if (static_cast <std::int64_t>(n) >= \
                                              kParallelMinParticles)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i)
    fill_row(il, static_cast<std::size_t>(i), model, bonds, dual, p, C);
  return il;
}

void rebuild_interaction_row(InteractionList& il, std::size_t i, ForceModel model,
                             const BondList& bonds, const DualList& dual, const ParticleStore& p,
                             const std::vector<double>& C) {
  const auto n = row_length(model, bonds, dual, i);
  il.live += n - il.rows.count[i];
  il.rows.make_room(i, n);
  fit_arena(il);
  fill_row(il, i, model, bonds, dual, p, C);
}

}  // namespace dhpd
