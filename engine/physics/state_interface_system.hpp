// The linear system of the state-based level-interface correction (docs/theory.md §20.6): the
// forces a unit homogeneous strain puts on each particle and the owners' dilatations, their
// derivative J with respect to the deviatoric factors φ = 1 + λ and dilatation factors ψ = 1 + ν
// of the unknown bonds (through the bond itself and, via θ, S and α, through every bond of its
// owner), and a block-Jacobi conjugate gradient on (J W⁻¹ Jᵀ + R) μ = rhs. Everything runs in a
// fixed order on one thread: the same bits for any thread count.
#pragma once
#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd::state_interface_detail {

/// Reference shape of entry k of row i: unit vector n from i to the other, |ξ|, and n·ε^q·n for
/// each unit strain ε^q (ε_ab = ε_ba = ½ off the diagonal).
struct EntryShape {
  double n[3] = {0, 0, 0};
  double length = 0.0;
  double stretch[6] = {0, 0, 0, 0, 0, 0};
};
EntryShape shape_of(const BondRows& rows, const ParticleStore& p, std::size_t i, std::int64_t k);

/// θ^q and α^q (docs/theory.md (20.7)) of every particle under each unit strain, with the model's
/// weights and every own bond counted.
class StrainStates {
 public:
  StrainStates(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model);
  double theta(std::size_t i, int q) const { return theta_[i * c_ + static_cast<std::size_t>(q)]; }
  double alpha(std::size_t i, int q) const { return alpha_[i * c_ + static_cast<std::size_t>(q)]; }

 private:
  std::size_t c_;
  std::vector<double> theta_, alpha_;
};

/// The force (not density) on particle i under each unit strain: out[q·n + a].
void strain_force_of(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
                     const StrainStates& states, std::size_t i, double* out);

using Block = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 18, 18>;

/// The weight of an owner's dilatation rows, times V_o κ_o/δ_o (about the force a whole
/// horizon's dilatation puts on it): large, so that θ stays the trace of every uniform strain.
inline constexpr double kThetaRowWeight = 100.0;

/// One bond with two unknowns, λ (deviatoric) and ν (dilatation): the own bond at `entry` from
/// `owner` to `other` (local indices), with g w (G), h w (H), |ξ|, n, n·ε^q·n (s), d^q = s^q −
/// θ_o^q/n, the weights W_λ = V_o G Q_o |ξ|² and W_ν = V_o H |ξ|² n² κ_o/m_o, and V_o |ξ| h w.
struct Unknown {
  std::int64_t entry;
  std::int32_t owner, other;
  double G, H, length, n[3], s[6], d[6], weight, dilatation_weight, dilatation;
};

/// An owner with unknowns: its local index, V_o, Q_o, κ_o, m_o, M_o = Σ g w |ξ|² over its own
/// bonds, α_o^q, its own bonds [first, last) in `partners`, its unknowns [first_unknown,
/// last_unknown) and the weight of its dilatation rows.
struct Owner {
  std::int32_t local;
  double volume, Q, kappa, m, second, alpha[6];
  std::int64_t first, last, first_unknown, last_unknown;
  double theta_weight;
};

/// One own bond of an owner: the partner's local index, V_o |ξ| h w, V_o |ξ| g w and n.
struct Partner {
  std::int32_t local;
  double coefficient, deviatoric, n[3];
};

/// The system over the particles whose forces the unknowns reach: the constrained particles first
/// (target: no force), then the owners' other partners (target: no change); after the force
/// blocks, each owner's dilatation under each unit strain (target: no change, θ stays the trace).
struct StateSystem {
  StateSystem(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
              const std::vector<std::int32_t>& constrained_particles);
  int dim, strains, size;  ///< size = dim × strains per particle
  std::vector<std::int32_t> particles;
  std::vector<std::uint8_t> constrained, touched;
  std::vector<Unknown> unknowns;
  std::vector<Owner> owners;
  std::vector<Partner> partners;
  Eigen::VectorXd forces;  ///< F_p^q before the correction, then the θ rows (zero)
  Eigen::VectorXd rhs;     ///< −F at constrained, 0 elsewhere, less each group's rigid part
  std::vector<Block> diag;
  std::vector<double> theta_diag;  ///< per θ row: its diagonal of J W⁻¹ Jᵀ
  /// Where owner o's θ rows start in the vectors.
  Eigen::Index theta_row(std::size_t o) const {
    return static_cast<Eigen::Index>(particles.size()) * size +
           static_cast<Eigen::Index>(o) * strains;
  }
  std::size_t unknown_count() const { return 2 * unknowns.size(); }
  double before = 0.0;  ///< largest |F_p| over the constrained particles
  auto block(Eigen::VectorXd& v, std::size_t k) const {
    return v.segment(static_cast<Eigen::Index>(k) * size, size);
  }
  auto block(const Eigen::VectorXd& v, std::size_t k) const {
    return v.segment(static_cast<Eigen::Index>(k) * size, size);
  }

 private:
  void collect(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
               const StrainStates& states, const std::vector<std::int32_t>& constrained_particles);
  void diagonal_blocks();
  void remove_rigid_parts(const ParticleStore& p);
};

/// The preconditioned conjugate gradient of (J W⁻¹ Jᵀ + R) μ = rhs, R_p = γ (D_p + tr(D_p)/size I)
/// on the approximate diagonal blocks D_p; x = W⁻¹ Jᵀ μ, the λ of every unknown bond then its ν.
class StateSolver {
 public:
  StateSolver(const StateSystem& sys, double gamma);
  int solve(Eigen::VectorXd& mu) const;
  std::vector<double> factors(const Eigen::VectorXd& mu) const;
  /// y += J x.
  void add_forward(const std::vector<double>& x, Eigen::VectorXd& y) const;
  /// g = Jᵀ μ.
  void adjoint(const Eigen::VectorXd& mu, std::vector<double>& g) const;

 private:
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  const StateSystem& sys_;
  std::vector<Block> reg_, inv_;
  std::vector<double> theta_reg_;  ///< per θ row: its regularisation
};

}  // namespace dhpd::state_interface_detail
