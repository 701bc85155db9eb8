// Interaction rows from bonds and dual bonds (IJNME 2016 eq. 27; CMAME 2017 §3, eq. 5).
#include "engine/interactions.hpp"
#include "engine/parallel.hpp"

namespace dhpd {

InteractionList build_interactions(ForceModel model, const BondList& bonds, const DualList& dual,
                                   const ParticleStore& p, const std::vector<double>& C) {
  const std::size_t n = bonds.particles();
  const bool with_dual = model == ForceModel::DualHorizon;
  // Classical BB-PD: c = 2C on each own bond, no reactions (IJNME 2016 §3.1).
  const double own_factor = with_dual ? 1.0 : 2.0;
  InteractionList il;
  il.offset.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto own = bonds.offset[i + 1] - bonds.offset[i];
    const auto duals = with_dual ? dual.offset[i + 1] - dual.offset[i] : 0;
    il.offset[i + 1] = il.offset[i] + own + duals;
  }
  const auto total = static_cast<std::size_t>(il.offset[n]);
  il.other.resize(total);
  il.inv_length.resize(total);
  il.coefficient.resize(total);
  il.own_slot.resize(bonds.size());
  il.dual_slot.assign(bonds.size(), -1);
#pragma omp parallel for schedule(static) if (static_cast <std::int64_t>(n) >= \
                                              kParallelMinParticles)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    std::int64_t k = il.offset[i];
    for (auto b = bonds.offset[i]; b < bonds.offset[i + 1]; ++b, ++k) {
      const auto j = bonds.neighbor[b];
      il.other[k] = j;
      il.inv_length[k] = 1.0 / bonds.length[b];
      il.coefficient[k] = own_factor * C[i] * bonds.weight[b] * p.volume[j] * bonds.intact[b];
      il.own_slot[b] = k;
    }
    if (!with_dual) continue;
    for (auto d = dual.offset[i]; d < dual.offset[i + 1]; ++d, ++k) {
      const auto b = dual.bond[d];
      const auto owner = bonds.owner[b];
      il.other[k] = owner;
      il.inv_length[k] = 1.0 / bonds.length[b];
      il.coefficient[k] = C[owner] * bonds.weight[b] * p.volume[owner] * bonds.intact[b];
      il.dual_slot[b] = k;
    }
  }
  return il;
}

}  // namespace dhpd
