// Ordinary state-based dual-horizon peridynamics (docs/theory.md §20; IJNME 2016 eq. 42, the
// linear peridynamic solid of Silling et al. 2007 in n = 1, 2, 3 dimensions): the force state of
// bond i→j uses the owner's weighted volume m_i, dilatation θ_i, κ_i and G_i; it acts on i and,
// reversed, on j (the dual horizon), so every pair gets equal and opposite impulses.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/discretization/section.hpp"
#include "engine/physics/material_law.hpp"

namespace dhpd {

/// Independent components of a symmetric strain in n dimensions: xx, yy, xy (2D); xx, yy, zz, xy,
/// xz, yz (3D); x (1D).
inline int strain_count(int n) {
  return n * (n + 1) / 2;
}
/// The axes (a, b) of strain component q in n dimensions.
inline void strain_axes(int n, int q, int& a, int& b) {
  static constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  const int k = n == 2 && q == 2 ? 3 : q;
  a = kPairs[k][0], b = kPairs[k][1];
}

/// ω of the bond from an owner of horizon `owner_horizon` at reference length |ξ| (§20.1).
inline double influence_of(Influence w, double owner_horizon, double length) {
  return w == Influence::Constant ? 1.0 : owner_horizon / length;
}

/// The state-based family's fracture factor Φ (docs/theory.md §20.4), s0 = sqrt(G0/(Φ δ)): G0 is
/// the energy the bonds crossing a crack plane hold when every bond is at s0 (the argument of IJNME
/// 2016 eq. 36), each bond's share of W_i being ½ t_ij e_ij V_j. At an isotropic stretch s that is
/// Φ s² δ with Φ = n² κ ∫_0^1 μ(ζ) dζ, μ(ζ) the share of m in the bonds crossing a plane ζδ away;
/// with ω = δ/|ξ| it is eq. 36's at bond-based PD's ν (1/3 plane stress, 1/4 in 3D and 1D).
double state_fracture_factor(const Material& m, const Section& s, Influence w);

/// What the state-based constants are built from.
struct OrdinaryStateInputs {
  Section section;
  ForceModel model = ForceModel::DualHorizon;
  PartialVolume rule = PartialVolume::None;
  Influence influence = Influence::Constant;
  const std::vector<Material>* materials = nullptr;
  /// Direction-dependent factors on each bond's dilatation and deviatoric terms from uniaxial
  /// strains (docs/theory.md §20.5); off: every factor 1.
  bool surface_correction = true;
};

/// Per row entry: the owner's factors h (dilatation) and g (deviatoric) along the bond, for the
/// entry's own bond and for the bond the other particle owns on this one (docs/theory.md §20.5).
struct SurfaceFactors {
  std::vector<double> own_dilatation, own_deviatoric, dual_dilatation, dual_deviatoric;
};

/// Each particle's factors under a uniaxial strain along each axis (the continuum's θ and
/// deviatoric energy over its own), read along a bond as the ellipse (ellipsoid) through them.
/// m and the own weights as OrdinaryState builds them.
SurfaceFactors surface_factors(const BondRows& rows, const ParticleStore& p,
                               const OrdinaryStateInputs& in, const std::vector<double>& m,
                               const std::vector<double>& own_weight);

/// The constants of every particle and row entry, the dilatation of the last pass, and the
/// passes themselves. Per particle (docs/theory.md §20.1):
///   m_i = Σ_{own bonds} ω β V_j |ξ|²                      (all own bonds, broken ones too)
///   θ_i = (n/m_i) Σ_{intact own bonds} ω β V_j |ξ| e       e = |y| − |ξ|
///   t_ij = ω (P_i |ξ| + Q_i e),  P_i = (n κ_i − (n+2) G_i) θ_i / m_i,  Q_i = n (n+2) G_i / m_i
/// (eq. 42 with e^d = e − θ|ξ|/n expanded), and the force density on i
///   f_i = Σ_entries [μ_ij ω β_ij V_j t_i + μ_ji ω β_ji V_j t_j] (y_j − y_i)/|y_j − y_i|.
/// The classical variable-horizon model (the original equation of motion with each particle's own
/// δ) sums over H_i only: t_i, and −t_j where j's horizon holds i too (ω_ji β_ij V_j, i's
/// quadrature); where it does not, nothing balances t_i: ghost forces where horizons differ.
class OrdinaryState {
 public:
  OrdinaryState() = default;
  /// Builds every constant for the rows as they are (all bonds intact or not: m counts both). The
  /// rows' factors φ and ψ (when allocated) scale each bond's deviatoric and dilatation weights:
  /// the level-interface correction of docs/theory.md §20.6 (engine/physics/state_interfaces.hpp).
  OrdinaryState(const BondRows& rows, const ParticleStore& p, const OrdinaryStateInputs& in);

  /// θ of every particle from the current positions, then the force density of every particle
  /// (overwritten), row by row in the gather form: the same bits for any thread count.
  /// With `subset`, only those particles' θ and forces (a rank's rows of a distributed run), and
  /// `between` runs after the dilatation pass (there every rank gets every θ, α, β: pass_fields).
  void forces(const BondRows& rows, ParticleStore& p, const std::vector<std::int32_t>* subset,
              const std::function<void()>& between);
  void forces(const BondRows& rows, ParticleStore& p) { forces(rows, p, nullptr, {}); }
  /// θ, α and β of each particle: what the force pass reads of a bond's other end.
  std::array<std::vector<double>*, 3> pass_fields() { return {&theta_, &alpha_, &beta_}; }
  /// The linearised forces of displacement u (dim values per particle) about the reference
  /// configuration, divided by each particle's density and negated: M⁻¹ K u per unit volume, the
  /// operator whose largest eigenvalue bounds the stable step (docs/theory.md §9, §20.3).
  void stiffness_times(const BondRows& rows, const ParticleStore& p, const std::vector<double>& u,
                       std::vector<double>& out);
  /// W_i = κ_i θ_i²/2 + (Q_i/2) Σ_{intact own} ω β V_j (e − θ_i |ξ|/n)² of every particle, from
  /// the current positions (θ recomputed).
  std::vector<double> energy_density(const BondRows& rows, const ParticleStore& p);
  /// Σ_i V_i W_i, summed in fixed blocks (the same bits for any thread count).
  double strain_energy(const BondRows& rows, const ParticleStore& p);
  /// The dilatation of the last pass.
  const std::vector<double>& dilatation() const { return theta_; }
  /// m_i of every particle.
  const std::vector<double>& weighted_volume() const { return m_; }
  /// κ_i and Q_i = n (n+2) G_i / m_i of every particle.
  const std::vector<double>& bulk() const { return bulk_; }
  const std::vector<double>& deviatoric_coefficient() const { return deviatoric_coefficient_; }
  /// Per row entry, the own bond's w h (dilatation) and w g φ (deviatoric) and the same of the bond
  /// the other particle owns on this one (w = ω β V_j, the owner's factors; §20.5, §20.6).
  const std::vector<double>& own_dilatation_weight() const { return own_dilatation_; }
  const std::vector<double>& own_deviatoric_weight() const { return own_weight_; }
  const std::vector<double>& dual_dilatation_weight() const { return dual_dilatation_; }
  const std::vector<double>& dual_deviatoric_weight() const { return dual_weight_; }
  /// The dimension n of the model.
  int dimension() const { return n_; }
  /// Multi-horizon α of each particle's interaction horizons (2i: toward −x, 2i + 1: toward +x;
  /// docs/theory.md §24); empty under the other models.
  const std::vector<double>& interaction_scale() const { return interaction_scale_; }
  std::size_t bytes() const;

 private:
  template <int Dim, class Kinematics>
  void dilatation_pass(const BondRows& rows, const ParticleStore& p, const Kinematics& kin,
                       const std::vector<std::int32_t>* subset = nullptr);
  template <int Dim, bool Multi, class Kinematics>
  void force_pass(const BondRows& rows, const ParticleStore& p, const Kinematics& kin,
                  double* const out[3], bool per_density,
                  const std::vector<std::int32_t>* subset = nullptr);

  /// Multiplies the deviatoric weights by the rows' factors φ and the dilatation weights by their
  /// dilatation factors ψ (docs/theory.md §20.6).
  void apply_interface_factors(const BondRows& rows);

 public:
  /// Multiplies the weights of the own bond at `entry` of row `owner`, and its side in the other
  /// row, by the bond's factors as the rows hold them now: for a bond whose factors were 1 when
  /// the model was built, the bits a new model of the rows would have.
  void scale_bond(const BondRows& rows, std::size_t owner, std::int64_t entry);

 private:
  /// Multi-horizon (multi_horizon_state.cpp): α per interaction horizon from eq. 7 with this
  /// model's integrand, the finer particle's interaction states in interaction_weight_ and the
  /// α-scaled states of both ends in the dual weights; dual_gate_ marks the entries whose dual
  /// term the row's own bond carries (the other end's interaction state).
  void use_multi_horizon(const BondRows& rows, const ParticleStore& p,
                         const OrdinaryStateInputs& in);

  int n_ = 3;
  bool classical_ = false;  ///< classical variable horizon: no dual bonds, ghost forces
  bool multi_ = false;      ///< multi-horizon (docs/theory.md §24)
  std::vector<double> interaction_scale_, interaction_weight_;
  /// Per row entry: α_θ ω_i V_j of i's interaction bond in its dilatation (multi-horizon).
  std::vector<double> interaction_theta_;
  std::vector<std::uint8_t> dual_gate_;
  std::vector<double> m_;                       ///< weighted volume
  std::vector<double> bulk_;                    ///< κ_i
  std::vector<double> deviatoric_coefficient_;  ///< Q_i = n (n+2) G_i / m_i
  std::vector<double> theta_;
  /// Per particle of the last pass (20.7): α = (n/m)(κθ − Q S/n), β = Q θ/n.
  std::vector<double> alpha_, beta_;
  /// Per row entry: w = ω β V_other of the own bond, and of the bond the other particle owns on
  /// this one (ω_ji β_ji V_j; classical variable horizon: ω_ji β_ij V_j where j's horizon holds
  /// i), times the owner's deviatoric surface factor g along the bond (§20.5; 1 without).
  std::vector<double> own_weight_, dual_weight_;
  /// The same w times the owner's dilatation factor h.
  std::vector<double> own_dilatation_, dual_dilatation_;
  /// |ξ| of each entry of the rows' table of distinct lengths (1 / inverse_lengths).
  std::vector<double> lengths_;
};

}  // namespace dhpd
