// Per-step loops over bonds: internal force, bond breaking, damage, strain energy, stable step.
// Formulas: docs/theory.md §4 (force), §9 (stable step), §7 (quadrature), §8 (damage); IJNME 2016
// eqs. 27, 44.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/interactions.hpp"

namespace dhpd {

/// Overwrites `force_density` with the internal force per unit volume of every particle:
/// f_i = Σ_k K_k β_k V_k s_k n_k, gathered row by row (no atomics, thread-count independent).
/// With `rows`, only those particles are updated. With `row_energy`, the same pass also writes
/// each updated row's Σ_k c_k s_k² |ξ_k| there (strain_energy_of_row_sums turns it into the
/// strain energy, the same bits as strain_energy_total of the state).
void internal_force_density(const InteractionList& il, ParticleStore& p,
                            const std::vector<std::int32_t>* rows = nullptr,
                            std::vector<double>* row_energy = nullptr);

/// internal_force_density of every row with bond breaking fused in: each intact bond with
/// s ≥ s0 of its owner (as the rows' break thresholds hold it; no_fail owners never break) is
/// zeroed in both rows of its pair and marked broken in `bonds` before the force is summed.
/// Every particle that lost an own bond gets its p.damage refreshed in the same pass, so damage
/// stays current as long as edits recompute it (Simulation does). Returns the number of bonds
/// broken by this call. `in` describes the same bonds and particles with the owners' constants (C,
/// s0). With `row_energy`, as internal_force_density: the row sums after the pass's breaks.
std::int64_t force_and_break(InteractionList& il, BondList& bonds, ParticleStore& p,
                             const RowInputs& in, std::vector<double>* row_energy = nullptr);

/// φ_i = 1 − Σ μ β V_j / Σ β V_j over own bonds (docs/theory.md §8); written to p.damage.
/// With `rows`, only those particles are updated.
void compute_damage(const BondList& bonds, ParticleStore& p,
                    const std::vector<std::int32_t>* rows = nullptr);

/// Strain-energy density of each particle from its own bonds: W_i = Σ_j ½ C_i β s² |ξ| V_j.
void strain_energy_density(const BondList& bonds, const ParticleStore& p,
                           const std::vector<double>& micromodulus, std::vector<double>& out);
/// Σ V_i W_i over the given rows, in their order (the strain energy those rows hold).
double strain_energy_of_rows(const BondList& bonds, const ParticleStore& p,
                             const std::vector<double>& micromodulus,
                             const std::vector<std::int32_t>& rows);

/// The total strain energy Σ_i V_i W_i from the interaction rows (docs/theory.md §3, §18): each
/// row entry carries the own and dual coefficients of its pair, c_k = Σ C_owner β φ V_other, so
/// Σ_i V_i Σ_k ¼ c_k s_k² |ξ_k| counts every intact bond once with ½ C β φ V_i V_j s² |ξ|. One pass
/// over the rows (no second walk of own bonds), summed per row then in row order: the same bits
/// for every thread count. Equals the sum over strain_energy_density to round-off.
double strain_energy_total(const InteractionList& il, const ParticleStore& p);
/// Σ_i ¼ V_i e_i in row order from the row sums e_i of a force pass (overwritten with the terms).
double strain_energy_of_row_sums(std::vector<double>& row_sums, const ParticleStore& p);

/// Quadrature diagnostic (V_i + Σ_{j∈H_i} β_ij V_j) / |ball(δ_i)| (docs/theory.md §7), over all own
/// bonds of the reference configuration (broken ones included; pre-cracked pairs have no bond).
/// 1 for a perfect quadrature of an interior particle's horizon.
void horizon_quadrature(const BondList& bonds, const ParticleStore& p, const Section& section,
                        std::vector<double>& out);

/// Largest stable step per docs/theory.md §9: min_i sqrt(2 ρ_i / Σ_k K_k β_k V_k / |ξ_k|) (no
/// safety).
double critical_time_step(const InteractionList& il, const ParticleStore& p);

/// The same bound per particle (infinite for a particle without bonds), resized to the store;
/// with `rows`, only those entries are recomputed.
void particle_time_steps(const InteractionList& il, const ParticleStore& p,
                         std::vector<double>& out, const std::vector<std::int32_t>* rows = nullptr);

/// The smallest entry (infinity for none): the stable step from particle_time_steps.
double smallest(const std::vector<double>& values);

/// Deterministic sum (fixed order, independent of threads).
double ordered_sum(const std::vector<double>& values);

}  // namespace dhpd
