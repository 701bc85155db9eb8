// How children of a refinement event get their displacement and velocity (docs/theory.md §13.4;
// IJNME 2016 §5.3 copies the parent's; the least-squares forms are ours, derived in docs/scenes.md
// `mapping`): fits over the parent's intact own bonds, exact for linear (or quadratic) fields.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "geometry/vec.hpp"

namespace dhpd::refine {

struct SplitPlan;

/// How children get their displacement u and velocity v from the parent q.
enum class StateMapping {
  /// The parent's u and v (the paper's; conserves momentum and kinetic energy, but neighbouring
  /// parents' children start with a jump of u: their short bonds carry about twice the strain).
  Copy,
  /// u_c = u_q + G_u (X_c − X_q) and v_c = v_q + G_v (X_c − X̄), G the least-squares gradient
  /// over q's intact own bonds weighted by β V_j, X̄ the centroid of the children created: a
  /// linear u is reproduced exactly (every new bond carries the field's stretch) and momentum is
  /// conserved exactly. The default.
  Linear,
  /// As Linear with a least-squares fit of gradient and Hessian: a quadratic u is reproduced
  /// exactly; the Hessian term of v is shifted by its mean over the siblings (momentum exact).
  Quadratic,
};

/// Scene names of the mappings, in the order of StateMapping.
inline constexpr const char* kStateMappingNames[] = {"copy", "linear", "quadratic"};
inline const char* mapping_name(StateMapping m) {
  return kStateMappingNames[static_cast<int>(m)];
}

/// The fit a parent got: full rank, a reduced rank (its intact bonds span fewer directions than
/// the space: the gradient along the unspanned ones is zero), or none (no intact bond: copy).
enum class FitRank { Full, Reduced, None };

struct ChildState {
  std::vector<geometry::Vec3> displacement, velocity;
  std::size_t reduced_fits = 0;  ///< parents whose fit had a reduced rank
};

/// The children's u and v, from the store and bonds before the event. `held` (sorted) lists the
/// particles with a prescribed velocity: a held region moves apart from the free material next
/// to it, so a fit never mixes held and free particles. `donor` (per child, or empty) names the
/// particle whose fit gives a child across a pre-crack from its parent its u and v
/// (`donors_across_cracks`); momentum stays exact (the siblings' mean change of v is removed).
ChildState map_state(const SplitPlan& plan, StateMapping mapping, const ParticleStore& p,
                     const BondRows& bonds, PartialVolume rule,
                     const std::vector<std::int32_t>& held,
                     const std::vector<std::int32_t>& donor = {});

/// A least-squares fit of a vector field w around particle i over its intact own bonds, weighted
/// by β V_j: w(X_i + ξ) ≈ w_i + G ξ (+ ½ ξᵀ H_r ξ per component r when quadratic).
struct FieldFit {
  double G[3][3] = {};  ///< G[r][a] = ∂w_r/∂X_a
  double H[3][6] = {};  ///< per component r: H_xx, H_yy, H_zz, H_xy, H_xz, H_yz (absent ones 0)
  FitRank rank = FitRank::None;

  /// The fitted change of w_r from the centre to the centre + o.
  double change(int r, const geometry::Vec3& o, int dim) const;
};

/// The fits of displacement and velocity around particle i (one normal matrix for both), over
/// its intact own bonds to particles on its side of `held` (see map_state). A quadratic fit whose
/// bonds cannot resolve a Hessian falls back to the linear fit.
struct ParentFit {
  FieldFit displacement, velocity;
};
ParentFit fit_parent(const ParticleStore& p, const BondRows& bonds, PartialVolume rule,
                     std::size_t i, bool quadratic, const std::vector<std::int32_t>& held = {});

}  // namespace dhpd::refine
