// Non-ordinary state-based (correspondence) dual-horizon PD for small-strain linear elasticity
// (docs/theory.md §21; IJNME 2016 eqs. 45–56; Euler–Lagrange paper eqs. 18–21): shape tensor and
// deformation gradient over the owner's horizon, Hooke's stress, force state ω σ K⁻¹ ξ on the
// owner and, reversed, on the other end; Silling's (2017) stabilisation of zero-energy modes.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/material_law.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd {

/// The stabilisation's stiffness as a fraction of the bond-based micromodulus of the same E and
/// horizon (docs/theory.md §21.2): G_s = kStabilisation · c(δ) / |ξ| per bond. 1: against finite
/// elements the vibrating plate at δ = 2Δx is 2.8 % off in v (0.1: 6.4 %), the static plate
/// 0.025 % (0.1: 0.006 %).
inline constexpr double kStabilisation = 1.0;

/// Per particle the shape tensor's inverse and Hooke's constants; per pass F, σ and the force.
class Correspondence {
 public:
  Correspondence() = default;
  /// `stabilisation`: the fraction of the bond-based micromodulus (0: none, which leaves the
  /// lattice's zero-energy modes).
  Correspondence(const BondRows& rows, const ParticleStore& p, const OrdinaryStateInputs& in,
                 double stabilisation = kStabilisation);

  /// Force density of every particle (overwritten) from the current positions.
  void forces(const BondRows& rows, ParticleStore& p) { forces(rows, p, nullptr, {}); }
  /// With `subset`, only those particles' state and forces (a rank's rows of a distributed run);
  /// `between` runs after the state pass (there every rank gets every F and σK⁻¹: pass_fields).
  void forces(const BondRows& rows, ParticleStore& p, const std::vector<std::int32_t>* subset,
              const std::function<void()>& between);
  /// F_i and σ_i K_i⁻¹ (9 values per particle each): what the force pass reads of a bond's other
  /// end.
  std::array<std::pair<double*, int>, 2> pass_fields() {
    return {std::pair{gradient_.data()->data(), 9}, std::pair{stress_kinv_.data()->data(), 9}};
  }
  /// M⁻¹ K u per unit volume for a displacement u (dim per particle): the model is linear in u.
  void stiffness_times(const BondRows& rows, const ParticleStore& p, const std::vector<double>& u,
                       std::vector<double>& out);
  /// Σ_i V_i W_i, W_i = ½ σ_i : ε_i + ½ Σ_j G_s ω β V_j |y_j − y_i − F_i ξ|² (the stabilisation).
  double strain_energy(const BondRows& rows, const ParticleStore& p);
  std::size_t bytes() const;

 private:
  using Tensor = std::array<double, 9>;  ///< row-major 3 × 3 (unused axes zero)
  template <int Dim>
  void state_pass(const BondRows& rows, const ParticleStore& p, const double* const y[3],
                  const std::vector<std::int32_t>* subset = nullptr);
  template <int Dim>
  void force_pass(const BondRows& rows, const ParticleStore& p, const double* const y[3],
                  double* const out[3], bool per_density,
                  const std::vector<std::int32_t>* subset = nullptr);

  std::vector<Tensor> shape_inverse_;  ///< K_i⁻¹ (the pseudo-inverse where the bonds do not span)
  std::vector<Tensor> span_;           ///< K_i⁺ K_i: the identity, or the projector onto the span
  std::vector<double> lambda_, mu_;    ///< Hooke's constants of the dimension
  std::vector<double> stab_;           ///< G_s · |ξ| = kStabilisation c(δ_i), per particle
  std::vector<Tensor> gradient_;       ///< F_i of the last pass
  std::vector<Tensor> stress_kinv_;    ///< σ_i K_i⁻¹ of the last pass
  std::vector<double> own_weight_, dual_weight_;  ///< ω β V_other, as OrdinaryState's
};

}  // namespace dhpd
