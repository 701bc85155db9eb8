// Ordinary state-based DH-PD: constants, dilatation and force passes (docs/theory.md §20; IJNME
// 2016 eq. 42).
#include "engine/physics/ordinary_state.hpp"

#include <cmath>
#include <numbers>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/multi_horizon.hpp"

namespace dhpd {
namespace {

/// Extension e = |y| − |ξ| and direction (y_j − y_i)/|y_j − y_i| in the current configuration.
struct Deformed {
  const double* y[3];
  template <int Dim>
  double at(std::size_t i, std::size_t j, double length, double dir[Dim]) const {
    double l2 = 0.0;
    for (int a = 0; a < Dim; ++a) {
      dir[a] = y[a][j] - y[a][i];
      l2 += dir[a] * dir[a];
    }
    const double l = std::sqrt(l2), inverse = 1.0 / l;
    for (int a = 0; a < Dim; ++a) dir[a] *= inverse;
    return l - length;
  }
  /// e alone (the dilatation pass needs no direction).
  template <int Dim>
  double extension(std::size_t i, std::size_t j, double length) const {
    double l2 = 0.0;
    for (int a = 0; a < Dim; ++a) {
      const double d = y[a][j] - y[a][i];
      l2 += d * d;
    }
    return std::sqrt(l2) - length;
  }
};

/// The same linearised about the reference configuration for a displacement u (Dim per
/// particle): e = n·(u_j − u_i), direction n = ξ/|ξ|.
struct Linearised {
  const double* x[3];
  const double* u;
  template <int Dim>
  double at(std::size_t i, std::size_t j, double length, double dir[Dim]) const {
    double e = 0.0;
    for (int a = 0; a < Dim; ++a) {
      dir[a] = (x[a][j] - x[a][i]) / length;
      e += dir[a] * (u[j * Dim + a] - u[i * Dim + a]);
    }
    return e;
  }
  template <int Dim>
  double extension(std::size_t i, std::size_t j, double length) const {
    double dir[Dim];
    return at<Dim>(i, j, length, dir);
  }
};

/// f(k, |ξ|, e) for every intact own bond of row i; |ξ| from `lengths` (the rows' 1/|ξ| table
/// inverted once: the bits of BondRows::length, without a division per entry).
template <int Dim, class Kinematics, class F>
void each_intact_own(const BondRows& rows, const double* lengths, std::size_t i,
                     const Kinematics& kin, F&& f) {
  for (auto k = rows.begin(i); k < rows.end(i); ++k) {
    if (!rows.own_intact(k)) continue;
    const double length = lengths[rows.length_index[k]];
    f(k, length, kin.template extension<Dim>(i, static_cast<std::size_t>(rows.other[k]), length));
  }
}

/// ∫_a^b f by Simpson's rule on `intervals` (even) intervals.
template <class F>
double simpson(F&& f, double a, double b, int intervals) {
  const double h = (b - a) / intervals;
  double sum = f(a) + f(b);
  for (int k = 1; k < intervals; ++k) sum += (k % 2 ? 4.0 : 2.0) * f(a + k * h);
  return sum * h / 3.0;
}

/// ∫ ω(r) r² dV over the bonds of a unit horizon that reach beyond a plane at distance z ≤ 1
/// (all bonds for z = 0 counted on both sides, i.e. the whole m when `whole`), with the measure of
/// the dimension: 1D points at ±r, 2D the arc where r sin φ > z, 3D the cap where r cos θ > z.
double second_moment(int n, Influence w, double z, bool whole) {
  const auto omega = [&](double r) { return w == Influence::Constant ? 1.0 : 1.0 / r; };
  const auto shell = [&](double r) {
    if (whole)
      return n == 1 ? 2.0 : (n == 2 ? 2.0 * std::numbers::pi * r : 4.0 * std::numbers::pi * r * r);
    if (r <= z) return 0.0;
    if (n == 1) return 1.0;
    if (n == 2) return (std::numbers::pi - 2.0 * std::asin(z / r)) * r;
    return 2.0 * std::numbers::pi * (1.0 - z / r) * r * r;
  };
  return simpson([&](double r) { return r > 0.0 ? omega(r) * r * r * shell(r) : 0.0; },
                 whole ? 0.0 : z, 1.0, 2000);
}

}  // namespace

double state_fracture_factor(const Material& m, const Section& s, Influence w) {
  const int n = s.dim;
  const double whole = second_moment(n, w, 0.0, true);
  // Every bond at s: t e = ω |ξ|² s² n² κ / m, so a bond's share ½ t e V_j of W_i is that
  // fraction of its m; those crossing the plane hold μ(z) = m_crossing(z)/m of κ n² s²/2.
  const auto crossing = [&](double z) { return second_moment(n, w, z, false) / whole; };
  return n * n * state_moduli(m, s).bulk * simpson(crossing, 0.0, 1.0, 200);
}

OrdinaryState::OrdinaryState(const BondRows& rows, const ParticleStore& p,
                             const OrdinaryStateInputs& in)
    : n_(in.section.dim),
      classical_(in.model == ForceModel::ClassicalVariable),
      multi_(in.model == ForceModel::MultiHorizon) {
  const std::size_t count = p.size();
  m_.assign(count, 0.0);
  bulk_.assign(count, 0.0);
  deviatoric_coefficient_.assign(count, 0.0);
  theta_.assign(count, 0.0);
  alpha_.assign(count, 0.0);
  beta_.assign(count, 0.0);
  own_weight_.assign(rows.flags.size(), 0.0);
  dual_weight_.assign(rows.flags.size(), 0.0);
  lengths_.resize(rows.inverse_lengths.size());
  for (std::size_t t = 0; t < lengths_.size(); ++t) lengths_[t] = 1.0 / rows.inverse_lengths[t];
  for_each_particle(count, [&](std::size_t i) {
    double m = 0.0;
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = rows.length(k);
      // Multi-horizon: a coarser particle is in i's interaction horizon, not its natural one.
      if (rows.has_own(k) && !(multi_ && coarser(p, j, i))) {
        own_weight_[k] = influence_of(in.influence, p.horizon[i], length) *
                         bond_weight(p, in.rule, i, j, length) * p.volume[j];
        m += own_weight_[k] * length * length;
        // Classical: −T_j<x_i − x_j> integrated over H_i (i's quadrature), where j's state has
        // that bond (i ∈ H_j); nothing where it has not (a ghost force).
        if (classical_ && rows.has_dual(k))
          dual_weight_[k] = influence_of(in.influence, p.horizon[j], length) *
                            bond_weight(p, in.rule, i, j, length) * p.volume[j];
      }
      if (!classical_ && rows.has_dual(k))
        dual_weight_[k] = influence_of(in.influence, p.horizon[j], length) *
                          bond_weight(p, in.rule, j, i, length) * p.volume[j];
    }
    m_[i] = m;
    if (!(m > 0.0)) return;  // no own bond: t = 0 for this owner
    const auto moduli =
        state_moduli((*in.materials)[static_cast<std::size_t>(p.material[i])], in.section);
    const double n = n_;
    bulk_[i] = moduli.bulk;
    deviatoric_coefficient_[i] = n * (n + 2.0) * moduli.shear / m;
  });
  // The factors only ever multiply the weights: each entry keeps the four products w h, w g of
  // its own bond and of the other's (SurfaceFactors; without the correction all four are w).
  own_dilatation_ = own_weight_;
  dual_dilatation_ = dual_weight_;
  if (multi_) use_multi_horizon(rows, p, in);  // without surface factors (refused with them)
  if (in.surface_correction && !multi_) {
    const SurfaceFactors f = surface_factors(rows, p, in, m_, own_weight_);
    for (std::size_t k = 0; k < rows.flags.size(); ++k) {
      own_dilatation_[k] *= f.own_dilatation[k];
      dual_dilatation_[k] *= f.dual_dilatation[k];
      own_weight_[k] *= f.own_deviatoric[k];
      dual_weight_[k] *= f.dual_deviatoric[k];
    }
  }
  if (!rows.factor.empty() || !rows.dilatation_factor.empty()) apply_interface_factors(rows);
}

void OrdinaryState::scale_bond(const BondRows& rows, std::size_t owner, std::int64_t entry) {
  const auto j = static_cast<std::size_t>(rows.other[entry]);
  const auto mirror = rows.find(j, static_cast<std::int32_t>(owner));
  own_weight_[entry] *= rows.own_factor(entry);
  own_dilatation_[entry] *= rows.own_dilatation_factor(entry);
  if (mirror >= 0 && rows.has_dual(mirror)) {
    dual_weight_[mirror] *= rows.own_factor(entry);
    dual_dilatation_[mirror] *= rows.own_dilatation_factor(entry);
  }
}

void OrdinaryState::apply_interface_factors(const BondRows& rows) {
  // The own bond's φ and ψ in its row; the other's from its entry in the other row (the same
  // bits).
  for_each_particle(rows.particles(), [&](std::size_t i) {
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      if (rows.has_own(k)) {
        own_weight_[k] *= rows.own_factor(k);
        own_dilatation_[k] *= rows.own_dilatation_factor(k);
      }
      if (rows.has_dual(k)) {
        const auto j = static_cast<std::size_t>(rows.other[k]);
        const auto mirror = rows.find(j, static_cast<std::int32_t>(i));
        dual_weight_[k] *= rows.own_factor(mirror);
        dual_dilatation_[k] *= rows.own_dilatation_factor(mirror);
      }
    }
  });
}

template <int Dim, class Kinematics>
void OrdinaryState::dilatation_pass(const BondRows& rows, const ParticleStore& p,
                                    const Kinematics& kin,
                                    const std::vector<std::int32_t>* subset) {
  for_each_particle(p.size(), subset, [&](std::size_t i) {
    // θ = (n/m) Σ h w |ξ| e;  S = Σ g w e^d |ξ| = Σ g w e |ξ| − (θ/n) Σ g w |ξ|² (§20.5).
    double theta = 0.0, extension = 0.0, moment = 0.0;
    each_intact_own<Dim>(rows, lengths_.data(), i, kin,
                         [&](std::int64_t k, double length, double e) {
                           theta += own_dilatation_[k] * length * e;
                           extension += own_weight_[k] * length * e;
                           moment += own_weight_[k] * length * length;
                         });
    if (multi_)  // the interaction horizon's share of θ (docs/theory.md §24)
      for (auto k = rows.begin(i); k < rows.end(i); ++k)
        if (interaction_theta_[k] != 0.0 && rows.dual_intact(k)) {
          const double length = lengths_[rows.length_index[k]];
          theta += interaction_theta_[k] * length *
                   kin.template extension<Dim>(i, static_cast<std::size_t>(rows.other[k]), length);
        }
    if (!(m_[i] > 0.0)) {
      theta_[i] = alpha_[i] = beta_[i] = 0.0;
      return;
    }
    theta_[i] = n_ * theta / m_[i];
    const double S = extension - theta_[i] * moment / n_, Q = deviatoric_coefficient_[i];
    alpha_[i] = n_ / m_[i] * (bulk_[i] * theta_[i] - Q * S / n_);
    beta_[i] = Q * theta_[i] / n_;
  });
}

template <int Dim, bool Multi, class Kinematics>
void OrdinaryState::force_pass(const BondRows& rows, const ParticleStore& p, const Kinematics& kin,
                               double* const out[3], bool per_density,
                               const std::vector<std::int32_t>* subset) {
  for_each_particle(p.size(), subset, [&](std::size_t i) {
    double f[Dim] = {};
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const bool own = rows.own_intact(k);
      bool dual = classical_ ? own && rows.dual_intact(k) : rows.dual_intact(k);
      bool interaction = false;
      if constexpr (Multi) {  // the gates of docs/theory.md §24
        if (dual_gate_[k]) dual = own;
        interaction = interaction_weight_[k] != 0.0 && rows.dual_intact(k);
      }
      if (!own && !dual && !interaction) continue;
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = lengths_[rows.length_index[k]];
      double dir[Dim];
      const double e = kin.template at<Dim>(i, j, length, dir);
      // t w = |ξ| (w h α − w g β) + w g Q e  (20.7), the owner's α, β, Q and factors.
      double t = 0.0;
      if (own)
        t += length * (own_dilatation_[k] * alpha_[i] - own_weight_[k] * beta_[i]) +
             own_weight_[k] * deviatoric_coefficient_[i] * e;
      if (dual)
        t += length * (dual_dilatation_[k] * alpha_[j] - dual_weight_[k] * beta_[j]) +
             dual_weight_[k] * deviatoric_coefficient_[j] * e;
      if constexpr (Multi)
        if (interaction)  // i's state over its interaction horizon, α-scaled (§24)
          t += interaction_weight_[k] *
               (length * (alpha_[i] - beta_[i]) + deviatoric_coefficient_[i] * e);
      for (int a = 0; a < Dim; ++a) f[a] += t * dir[a];
    }
    for (int a = 0; a < Dim; ++a) out[a][i] = per_density ? -f[a] / p.density[i] : f[a];
  });
}

void OrdinaryState::forces(const BondRows& rows, ParticleStore& p,
                           const std::vector<std::int32_t>* subset,
                           const std::function<void()>& between) {
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const Deformed kin{{p.position[0].data(), p.position[1].data(), p.position[2].data()}};
    dilatation_pass<Dim>(rows, p, kin, subset);
    if (between) between();
    double* const out[3] = {p.force_density[0].data(), p.force_density[1].data(),
                            p.force_density[2].data()};
    if (multi_)  // the kernel is chosen once per pass, not per bond
      force_pass<Dim, true>(rows, p, kin, out, false, subset);
    else
      force_pass<Dim, false>(rows, p, kin, out, false, subset);
    return 0;
  });
}

void OrdinaryState::stiffness_times(const BondRows& rows, const ParticleStore& p,
                                    const std::vector<double>& u, std::vector<double>& out) {
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const auto& X = p.reference_position;
    const Linearised kin{{X[0].data(), X[1].data(), X[2].data()}, u.data()};
    dilatation_pass<Dim>(rows, p, kin);
    // out is interleaved (Dim per particle): write axis a of particle i at i·Dim + a.
    std::vector<double> axes[3];
    for (int a = 0; a < Dim; ++a) axes[a].resize(p.size());
    double* const target[3] = {axes[0].data(), axes[1].data(), axes[2].data()};
    if (multi_)
      force_pass<Dim, true>(rows, p, kin, target, true);
    else
      force_pass<Dim, false>(rows, p, kin, target, true);
    out.resize(p.size() * Dim);
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int a = 0; a < Dim; ++a) out[i * Dim + a] = axes[a][i];
    return 0;
  });
}

std::vector<double> OrdinaryState::energy_density(const BondRows& rows, const ParticleStore& p) {
  std::vector<double> energy(p.size(), 0.0);
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const Deformed kin{{p.position[0].data(), p.position[1].data(), p.position[2].data()}};
    dilatation_pass<Dim>(rows, p, kin);
    for_each_particle(p.size(), [&](std::size_t i) {
      double deviatoric = 0.0;
      each_intact_own<Dim>(rows, lengths_.data(), i, kin,
                           [&](std::int64_t k, double length, double e) {
                             const double ed = e - theta_[i] * length / n_;
                             deviatoric += own_weight_[k] * ed * ed;
                           });
      energy[i] =
          0.5 * bulk_[i] * theta_[i] * theta_[i] + 0.5 * deviatoric_coefficient_[i] * deviatoric;
    });
    return 0;
  });
  return energy;
}

double OrdinaryState::strain_energy(const BondRows& rows, const ParticleStore& p) {
  auto energy = energy_density(rows, p);
  for (std::size_t i = 0; i < energy.size(); ++i) energy[i] *= p.volume[i];
  return ordered_sum(energy);
}

std::size_t OrdinaryState::bytes() const {
  std::size_t b = 0;
  for (const auto* v : {&m_, &bulk_, &deviatoric_coefficient_, &theta_, &alpha_, &beta_,
                        &own_weight_, &dual_weight_, &own_dilatation_, &dual_dilatation_})
    b += v->capacity() * sizeof(double);
  return b;
}

}  // namespace dhpd
