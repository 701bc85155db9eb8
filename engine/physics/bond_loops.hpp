// Per-step loops over bonds: internal force, bond breaking, damage, strain energy, stable step.
// Formulas: docs/theory.md §4 (force), §9 (stable step), §7 (quadrature), §8 (damage); IJNME 2016
// eqs. 27, 44.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/force_kernel.hpp"
#include "engine/physics/interactions.hpp"

namespace dhpd {

/// Overwrites `force_density` with the internal force per unit volume of every particle:
/// f_i = Σ_k K_k β_k V_k s_k n_k, gathered row by row (no atomics, thread-count independent).
/// With `rows`, only those particles are updated. With `row_energy`, the same pass also writes
/// each updated row's Σ_k c_k s_k² |ξ_k| there (strain_energy_of_row_sums turns it into the
/// strain energy, the same bits as strain_energy_total of the state). `points` is the kernel's
/// packed positions and volumes (kernel::PackedPoints), kept by a caller that steps often so no
/// step allocates.
void internal_force_density(const BondRows& bonds, ParticleStore& p,
                            const std::vector<std::int32_t>* rows = nullptr,
                            std::vector<double>* row_energy = nullptr,
                            kernel::PackedPoints* points = nullptr, const SideTask* side = nullptr);

/// internal_force_density of every row with bond breaking fused in: each intact bond with
/// s ≥ s0 of its owner (no_fail owners never break) is marked broken in both rows of its pair
/// (each row decides from the same bits) and the entry's stiffness updated before the force is
/// summed. Every particle that lost an own bond gets its p.damage refreshed in the same pass, so
/// damage stays current as long as edits recompute it (Simulation does). Returns the number of
/// bonds broken by this call. `c` describes the same rows and particles. With `row_energy`, as
/// internal_force_density: the row sums after the pass's breaks. Both run `side` (when given and
/// not empty) once, on one thread of the pass (SideTask). With `rows`, only those particles' rows
/// (a rank's share of a distributed run: docs/theory.md §25.1).
std::int64_t force_and_break(BondRows& bonds, ParticleStore& p, const BondConstants& c,
                             std::vector<double>* row_energy = nullptr,
                             kernel::PackedPoints* points = nullptr, const SideTask* side = nullptr,
                             const std::vector<std::int32_t>* rows = nullptr,
                             const kernel::StretchWatch& watch = {});

/// The break test alone (no forces), for the state-based family, whose forces need every
/// particle's dilatation after the breaks: each intact bond whose stretch reached its owner's s0
/// breaks in both rows of its pair (each row decides from the same bits, as force_and_break), and
/// a row that lost an own bond refreshes its damage. Returns the bonds broken.
/// With `rows`, only those rows (a rank's share of a distributed run).
std::int64_t break_bonds(BondRows& bonds, ParticleStore& p, const BondConstants& c,
                         const std::vector<std::int32_t>* rows = nullptr);

/// One time level's part of the rows (docs/theory.md §19): rows `rows`, each only its entries
/// [start[i], start[i] + count[i]), forces written to `force` (the other rows' are left alone).
struct RowSegments {
  const std::vector<std::int32_t>& rows;
  const std::int64_t* start;
  const std::int32_t* count;
  VectorArray& force;
};

/// internal_force_density over row segments, with bond breaking fused in when `c` is given
/// (force_and_break: a row that lost an own bond gets its whole damage refreshed). Reads the
/// neighbours from `points`, which must hold the current positions (not packed here). Returns
/// the bonds broken; `side` as internal_force_density.
std::int64_t segment_forces(BondRows& bonds, ParticleStore& p, const BondConstants* c,
                            const RowSegments& seg, const std::vector<double>& points,
                            const SideTask* side = nullptr, const kernel::StretchWatch& watch = {});

/// φ_i = 1 − Σ μ β V_j / Σ β V_j over own bonds (docs/theory.md §8); written to p.damage.
/// With `subset`, only those particles are updated.
void compute_damage(const BondRows& bonds, ParticleStore& p, PartialVolume rule,
                    const std::vector<std::int32_t>* subset = nullptr);

/// Strain-energy density of each particle from its intact own bonds:
/// W_i = Σ_j ½ C_i β φ s² |ξ| V_j (in double precision, from the constants).
void strain_energy_density(const BondRows& bonds, const BondConstants& c, std::vector<double>& out);
/// Σ_i ¼ V_i Σ_k c_k s_k² |ξ_k| over the given rows, in their order: their share of
/// strain_energy_total, term for term the same bits (an edit's energy ledger counts the rows it
/// changes before and after; unchanged rows cancel).
double strain_energy_of_rows(const BondRows& bonds, const ParticleStore& p,
                             const std::vector<std::int32_t>& rows);

/// The total strain energy Σ_i V_i W_i from the bond rows (docs/theory.md §3, §18): each row
/// entry carries the pair stiffness of its intact bonds, c_k = K_k V_other, so
/// Σ_i V_i Σ_k ¼ c_k s_k² |ξ_k| counts every intact bond once with ½ C β φ V_i V_j s² |ξ|. One pass
/// over the rows (no second walk of own bonds), summed per row then in row order: the same bits
/// for every thread count. Equals the sum over strain_energy_density to the single-precision
/// rounding of K.
double strain_energy_total(const BondRows& bonds, const ParticleStore& p);
/// Σ_i ¼ V_i e_i in row order from the row sums e_i of a force pass (overwritten with the terms).
double strain_energy_of_row_sums(std::vector<double>& row_sums, const ParticleStore& p);

/// Quadrature diagnostic (V_i + Σ_{j∈H_i} β_ij V_j) / |ball(δ_i)| (docs/theory.md §7), over all own
/// bonds of the reference configuration (broken ones included; pre-cracked pairs have no bond).
/// 1 for a perfect quadrature of an interior particle's horizon.
void horizon_quadrature(const BondRows& bonds, const ParticleStore& p, PartialVolume rule,
                        const Section& section, std::vector<double>& out);

/// Largest stable step per docs/theory.md §9: min_i sqrt(2 ρ_i / Σ_k K_k β_k V_k / |ξ_k|) (no
/// safety).
double critical_time_step(const BondRows& bonds, const ParticleStore& p);

/// The same bound per particle (infinite for a particle without bonds), resized to the store;
/// with `rows`, only those entries are recomputed.
void particle_time_steps(const BondRows& bonds, const ParticleStore& p, std::vector<double>& out,
                         const std::vector<std::int32_t>* rows = nullptr);

/// The smallest entry (infinity for none): the stable step from particle_time_steps.
double smallest(const std::vector<double>& values);

/// Deterministic sum (fixed order, independent of threads).
double ordered_sum(const std::vector<double>& values);
/// The blocks of ordered_sum: each summed in order, then their sums in order.
inline constexpr std::int64_t kOrderedSumBlock = 4096;

}  // namespace dhpd
