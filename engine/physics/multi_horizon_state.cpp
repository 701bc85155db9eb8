// Multi-horizon PD for the ordinary state-based family (CMES 2019 §2, eqs. 3–7; docs/theory.md
// §24): α from eq. 7 with the linear peridynamic solid's integrand, and the row weights that
// carry the interaction states.
#include <array>
#include <cmath>

#include "engine/base/errors.hpp"
#include "engine/physics/multi_horizon.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd {

void OrdinaryState::use_multi_horizon(const BondRows& rows, const ParticleStore& p,
                                      const OrdinaryStateInputs& in) {
  // Under a uniform stretch ε every natural state is t = κ ε ω |ξ| / m (1D: the deviatoric part
  // vanishes), so the refined material's integrand T − T′ is 2 κ_i ε ω_i r / m_i per volume and
  // the interaction horizon's (κ_i ω_i / m_i + κ_j ω_j / m_j) ε |ξ| (eq. 7, per side).
  const std::size_t n = p.size();
  // m_i over the horizon a refined body would give i: its natural bonds and the part of its ball
  // coarser cells occupy; θ's share of that part is carried by the interaction bonds, scaled by
  // α_θ = m_occupied / Σ ω_i |ξ|² V_j per side, so that a uniform stretch gives θ = ε.
  std::vector<double> occupied_m(2 * n, 0.0), refined(2 * n, 0.0), carried(2 * n, 0.0);
  // The refined material is i's own lattice continued into the coarser cells: virtual particles
  // at k ℓ_i, with i's partial-volume rule, so that m_i and the refined integrand are exactly
  // those of a particle of a uniform fine lattice.
  for_each_coarser_overlap(p, [&](std::size_t i, std::size_t side, double r0, double r1) {
    const double h = p.spacing[i], delta = p.horizon[i], volume = p.volume[i];
    for (auto k = static_cast<long>(std::ceil(r0 / h - 1e-9)); k * h < r1 - 1e-12 * h; ++k) {
      const double r = static_cast<double>(k) * h;
      if (r <= 0.0 || r < r0 - 1e-12 * h) continue;
      const double w = influence_of(in.influence, delta, r) *
                       partial_volume_factor(in.rule, 1, r, delta, 0.5 * h) * volume;
      occupied_m[2 * i + side] += w * r * r;
      refined[2 * i + side] += w * r;
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    const double extra = occupied_m[2 * i] + occupied_m[2 * i + 1];
    if (extra == 0.0 || !(m_[i] > 0.0)) continue;
    deviatoric_coefficient_[i] *= m_[i] / (m_[i] + extra);
    m_[i] += extra;
  }
  for (std::size_t s = 0; s < 2 * n; ++s)
    if (m_[s / 2] > 0.0) refined[s] *= 2.0 * bulk_[s / 2] / m_[s / 2];
  std::vector<double> theta_carried(2 * n, 0.0);
  const auto state_per_volume = [&](std::size_t owner, double length) {
    return m_[owner] > 0.0 ? bulk_[owner] * influence_of(in.influence, p.horizon[owner], length) *
                                 length / m_[owner]
                           : 0.0;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      if (!coarser(p, j, i) || !rows.has_dual(k)) continue;
      const double length = rows.length(k);
      const auto s = 2 * i + side_of(p, i, j);
      carried[s] += (state_per_volume(i, length) + state_per_volume(j, length)) * p.volume[j];
      theta_carried[s] +=
          influence_of(in.influence, p.horizon[i], length) * length * length * p.volume[j];
    }
  interaction_scale_.assign(2 * n, 0.0);
  std::vector<double> theta_scale(2 * n, 0.0);
  for (std::size_t s = 0; s < 2 * n; ++s) {
    if (carried[s] > 0.0) interaction_scale_[s] = refined[s] / carried[s];
    if (theta_carried[s] > 0.0) theta_scale[s] = occupied_m[s] / theta_carried[s];
  }
  // The weights: i's interaction state (α_i ω_i V_j, its own bond in neither m_i nor θ_i), j's
  // state toward i scaled by α_i; in the coarser particle's row the finer one's interaction state
  // (α ω V), carried by the coarser particle's own bond.
  interaction_weight_.assign(rows.flags.size(), 0.0);
  interaction_theta_.assign(rows.flags.size(), 0.0);
  dual_gate_.assign(rows.flags.size(), 0);
  for (std::size_t i = 0; i < n; ++i)
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = rows.length(k);
      if (coarser(p, j, i)) {
        const auto s = 2 * i + side_of(p, i, j);
        const double a = interaction_scale_[s];
        const double w = influence_of(in.influence, p.horizon[i], length) * p.volume[j];
        interaction_weight_[k] = a * w;
        if (rows.has_dual(k)) interaction_theta_[k] = theta_scale[s] * w;
        dual_weight_[k] *= a;
        dual_dilatation_[k] = dual_weight_[k];
      } else if (coarser(p, i, j)) {
        const double a = interaction_scale_[2 * j + side_of(p, j, i)];
        dual_weight_[k] = a * influence_of(in.influence, p.horizon[j], length) * p.volume[j];
        dual_dilatation_[k] = dual_weight_[k];
        dual_gate_[k] = 1;
      }
    }
}

}  // namespace dhpd
