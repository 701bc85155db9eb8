// The state-based level-interface system and its solve (docs/theory.md §20.6).
#include "engine/physics/state_interface_system.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/base/parallel.hpp"

namespace dhpd::state_interface_detail {

EntryShape shape_of(const BondRows& rows, const ParticleStore& p, std::size_t i, std::int64_t k) {
  const int n = p.dim();
  EntryShape s;
  const auto j = static_cast<std::size_t>(rows.other[k]);
  s.length = rows.length(k);
  for (int a = 0; a < n; ++a)
    s.n[a] = (p.reference_position[a][j] - p.reference_position[a][i]) / s.length;
  for (int q = 0; q < strain_count(n); ++q) {
    int a = 0, b = 0;
    strain_axes(n, q, a, b);
    s.stretch[q] = s.n[a] * s.n[b];
  }
  return s;
}

StrainStates::StrainStates(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model)
    : c_(static_cast<std::size_t>(strain_count(model.dimension()))) {
  const int n = model.dimension();
  theta_.assign(p.size() * c_, 0.0);
  alpha_.assign(p.size() * c_, 0.0);
  const auto& H = model.own_dilatation_weight();
  const auto& G = model.own_deviatoric_weight();
  for_each_particle(p.size(), [&](std::size_t i) {
    const double m = model.weighted_volume()[i];
    if (!(m > 0.0)) return;
    double theta[6] = {}, moment[6] = {}, second = 0.0;
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      if (!rows.has_own(k)) continue;
      const auto s = shape_of(rows, p, i, k);
      const double l2 = s.length * s.length;
      second += G[k] * l2;
      for (std::size_t q = 0; q < c_; ++q) {
        theta[q] += H[k] * l2 * s.stretch[q];
        moment[q] += G[k] * l2 * s.stretch[q];
      }
    }
    const double Q = model.deviatoric_coefficient()[i], kappa = model.bulk()[i];
    for (std::size_t q = 0; q < c_; ++q) {
      const double t = n * theta[q] / m, S = moment[q] - t * second / n;
      theta_[i * c_ + q] = t;
      alpha_[i * c_ + q] = n / m * (kappa * t - Q * S / n);
    }
  });
}

void strain_force_of(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
                     const StrainStates& states, std::size_t i, double* out) {
  const int n = model.dimension(), c = strain_count(n);
  for (int k = 0; k < c * n; ++k) out[k] = 0.0;
  const auto& Q = model.deviatoric_coefficient();
  for (auto k = rows.begin(i); k < rows.end(i); ++k) {
    const bool own = rows.has_own(k), dual = rows.has_dual(k);
    if (!own && !dual) continue;
    const auto j = static_cast<std::size_t>(rows.other[k]);
    const auto s = shape_of(rows, p, i, k);
    for (int q = 0; q < c; ++q) {
      double t = 0.0;  // (20.7) linearised: |ξ| h w α + g w Q |ξ| (n·ε·n − θ/n)
      if (own)
        t += s.length *
             (model.own_dilatation_weight()[k] * states.alpha(i, q) +
              model.own_deviatoric_weight()[k] * Q[i] * (s.stretch[q] - states.theta(i, q) / n));
      if (dual)
        t += s.length *
             (model.dual_dilatation_weight()[k] * states.alpha(j, q) +
              model.dual_deviatoric_weight()[k] * Q[j] * (s.stretch[q] - states.theta(j, q) / n));
      for (int a = 0; a < n; ++a) out[q * n + a] += p.volume[i] * t * s.n[a];
    }
  }
}

StateSystem::StateSystem(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
                         const std::vector<std::int32_t>& constrained_particles)
    : dim(model.dimension()), strains(strain_count(dim)), size(dim * strains) {
  const StrainStates states(rows, p, model);
  collect(rows, p, model, states, constrained_particles);
  const auto blocks = particles.size();
  forces = Eigen::VectorXd::Zero(theta_row(owners.size()));
  rhs = forces;
  for (std::size_t k = 0; k < blocks; ++k)
    strain_force_of(rows, p, model, states, static_cast<std::size_t>(particles[k]),
                    forces.data() + static_cast<std::ptrdiff_t>(k) * size);
  diagonal_blocks();
  for (std::size_t k = 0; k < blocks; ++k) {
    if (constrained[k]) before = std::max(before, block(forces, k).norm());
    if (constrained[k] && touched[k]) block(rhs, k) = -block(forces, k);
  }
  remove_rigid_parts(p);
}

namespace {

/// Gathers the system's owners, unknowns and partners from the rows (StateSystem::collect).
struct Collector {
  StateSystem& sys;
  const BondRows& rows;
  const ParticleStore& p;
  const OrdinaryState& model;
  const StrainStates& states;
  std::vector<std::int32_t> local;  ///< particle -> its place in sys.particles, or −1

  Owner owner_of(std::size_t i) const {
    const double kappa = model.bulk()[i];
    Owner o{local[i],
            p.volume[i],
            model.deviatoric_coefficient()[i],
            kappa,
            model.weighted_volume()[i],
            0.0,
            {},
            static_cast<std::int64_t>(sys.partners.size()),
            0,
            static_cast<std::int64_t>(sys.unknowns.size()),
            0,
            // θ rows as stiff as the force a whole horizon's dilatation puts on o
            kThetaRowWeight * p.volume[i] * kappa / p.horizon[i]};
    for (int q = 0; q < sys.strains; ++q) o.alpha[q] = states.alpha(i, q);
    return o;
  }

  /// Every own bond of i to another constrained particle, both its weights positive.
  void add_unknowns(std::size_t i, Owner& o) {
    const auto& H = model.own_dilatation_weight();
    const auto& G = model.own_deviatoric_weight();
    const double n = sys.dim;
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      if (!rows.has_own(k)) continue;
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const auto s = shape_of(rows, p, i, k);
      const double l2 = s.length * s.length;
      o.second += G[k] * l2;
      const double weight = p.volume[i] * G[k] * o.Q * l2;
      const double dilatation_weight = p.volume[i] * H[k] * l2 * n * n * o.kappa / o.m;
      if (local[j] < 0 || !sys.constrained[static_cast<std::size_t>(local[j])] || !(weight > 0.0) ||
          !(dilatation_weight > 0.0))
        continue;
      Unknown u{k,
                local[i],
                local[j],
                G[k],
                H[k],
                s.length,
                {s.n[0], s.n[1], s.n[2]},
                {},
                {},
                weight,
                dilatation_weight,
                p.volume[i] * s.length * H[k]};
      for (int q = 0; q < sys.strains; ++q) {
        u.s[q] = s.stretch[q];
        u.d[q] = s.stretch[q] - states.theta(i, q) / n;
      }
      sys.unknowns.push_back(u);
    }
  }

  /// Every own bond of i: α's change reaches each partner (added as a no-change particle).
  void add_partners(std::size_t i) {
    const auto& H = model.own_dilatation_weight();
    const auto& G = model.own_deviatoric_weight();
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      if (!rows.has_own(k)) continue;
      const auto j = static_cast<std::size_t>(rows.other[k]);
      if (local[j] < 0) {
        local[j] = static_cast<std::int32_t>(sys.particles.size());
        sys.particles.push_back(static_cast<std::int32_t>(j));
        sys.constrained.push_back(0);
      }
      const auto s = shape_of(rows, p, i, k);
      sys.partners.push_back({local[j],
                              p.volume[i] * s.length * H[k],
                              p.volume[i] * s.length * G[k],
                              {s.n[0], s.n[1], s.n[2]}});
    }
  }
};

}  // namespace

void StateSystem::collect(const BondRows& rows, const ParticleStore& p, const OrdinaryState& model,
                          const StrainStates& states,
                          const std::vector<std::int32_t>& constrained_particles) {
  Collector c{*this, rows, p, model, states, std::vector<std::int32_t>(p.size(), -1)};
  for (const auto i : constrained_particles) {
    c.local[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(particles.size());
    particles.push_back(i);
  }
  constrained.assign(particles.size(), 1);
  for (const auto o : constrained_particles) {
    const auto i = static_cast<std::size_t>(o);
    if (!(model.weighted_volume()[i] > 0.0)) continue;
    Owner owner = c.owner_of(i);
    c.add_unknowns(i, owner);
    owner.last_unknown = static_cast<std::int64_t>(unknowns.size());
    if (owner.last_unknown == owner.first_unknown) continue;
    c.add_partners(i);
    owner.last = static_cast<std::int64_t>(partners.size());
    owners.push_back(owner);
  }
}

namespace {

using Column = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 18, 1>;

/// The columns of J of one bond's λ and ν at its owner and its other end, squared into their
/// diagonal blocks; the owner's other partners get a scalar share on `scalar` (their columns
/// are α's and θ's change alone); the owner's θ rows their diagonal.
void add_bond_columns(StateSystem& sys, std::size_t oi, const Unknown& u, const double sH[3],
                      const double sG[3], std::vector<double>& scalar) {
  const auto& o = sys.owners[oi];
  const int dim = sys.dim, strains = sys.strains;
  const double n = dim, l2 = u.length * u.length;
  const double through_theta = n / o.m * (o.kappa + o.Q * o.second / (n * n));
  Column vo(sys.size), vj(sys.size);
  // λ: direct V_o G Q |ξ| d^q n, through α: −(Q/m) G |ξ|² d^q (Σ_e V_o |ξ| h w n_e).
  for (int q = 0; q < strains; ++q)
    for (int a = 0; a < dim; ++a) {
      const double direct = o.volume * u.G * o.Q * u.length * u.d[q];
      const double via = -o.Q / o.m * u.G * l2 * u.d[q];
      vo[q * dim + a] = direct * u.n[a] + via * sH[a];
      vj[q * dim + a] = -direct * u.n[a] - via * u.dilatation * u.n[a];
    }
  sys.diag[static_cast<std::size_t>(u.owner)] += vo * vo.transpose() / u.weight;
  sys.diag[static_cast<std::size_t>(u.other)] += vj * vj.transpose() / u.weight;
  // ν: direct V_o |ξ| h w α^q n, through θ: dθ^q = (n/m) H |ξ|² s^q times
  // (through_theta Σ V_o |ξ| h w n − (Q/n) Σ V_o |ξ| g w n).
  double dtheta[6] = {};
  for (int q = 0; q < strains; ++q) dtheta[q] = n / o.m * u.H * l2 * u.s[q];
  const double self = through_theta * u.dilatation - o.Q / n * (u.dilatation * u.G / u.H);
  for (int q = 0; q < strains; ++q)
    for (int a = 0; a < dim; ++a) {
      const double direct = u.dilatation * o.alpha[q];
      vo[q * dim + a] = direct * u.n[a] + dtheta[q] * (through_theta * sH[a] - o.Q / n * sG[a]);
      vj[q * dim + a] = -direct * u.n[a] - dtheta[q] * self * u.n[a];
    }
  sys.diag[static_cast<std::size_t>(u.owner)] += vo * vo.transpose() / u.dilatation_weight;
  sys.diag[static_cast<std::size_t>(u.other)] += vj * vj.transpose() / u.dilatation_weight;
  double d2 = 0.0, t2 = 0.0;
  for (int q = 0; q < strains; ++q) {
    const double t = o.theta_weight * dtheta[q];
    sys.theta_diag[oi * static_cast<std::size_t>(strains) + static_cast<std::size_t>(q)] +=
        t * t / u.dilatation_weight;
    d2 += u.d[q] * u.d[q], t2 += dtheta[q] * dtheta[q];
  }
  sys.touched[static_cast<std::size_t>(u.owner)] = sys.touched[static_cast<std::size_t>(u.other)] =
      1;
  for (auto e = o.first; e < o.last; ++e) {
    const auto& pe = sys.partners[static_cast<std::size_t>(e)];
    if (pe.local == u.other) continue;
    const double v = o.Q / o.m * u.G * l2 * pe.coefficient;
    const double w = through_theta * pe.coefficient - o.Q / n * pe.deviatoric;
    scalar[static_cast<std::size_t>(pe.local)] +=
        (d2 * v * v / u.weight + t2 * w * w / u.dilatation_weight) / sys.size;
    sys.touched[static_cast<std::size_t>(pe.local)] = 1;
  }
}

}  // namespace

void StateSystem::diagonal_blocks() {
  const auto blocks = particles.size();
  diag.assign(blocks, Block::Zero(size, size));
  theta_diag.assign(owners.size() * static_cast<std::size_t>(strains), 0.0);
  std::vector<double> scalar(blocks, 0.0);
  touched.assign(blocks, 0);
  for (std::size_t oi = 0; oi < owners.size(); ++oi) {
    const auto& o = owners[oi];
    double sH[3] = {0, 0, 0}, sG[3] = {0, 0, 0};  // Σ_e V_o |ξ| (h w, g w) n_e
    for (auto e = o.first; e < o.last; ++e)
      for (int a = 0; a < dim; ++a) {
        sH[a] += partners[static_cast<std::size_t>(e)].coefficient * partners[e].n[a];
        sG[a] += partners[static_cast<std::size_t>(e)].deviatoric * partners[e].n[a];
      }
    for (auto b = o.first_unknown; b < o.last_unknown; ++b)
      add_bond_columns(*this, oi, unknowns[static_cast<std::size_t>(b)], sH, sG, scalar);
  }
  for (std::size_t k = 0; k < blocks; ++k) diag[k].diagonal().array() += scalar[k];
}

namespace {

/// The touched particles in groups linked through an owner (its unknowns reach all its partners).
std::vector<std::vector<std::size_t>> touched_groups(const StateSystem& sys) {
  const auto blocks = sys.particles.size();
  std::vector<std::int32_t> root(blocks);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](std::int32_t k) {
    while (root[static_cast<std::size_t>(k)] != k)
      k = root[static_cast<std::size_t>(k)] =
          root[static_cast<std::size_t>(root[static_cast<std::size_t>(k)])];
    return k;
  };
  for (const auto& o : sys.owners)
    for (auto e = o.first; e < o.last; ++e) {
      const auto a = find(o.local), b = find(sys.partners[static_cast<std::size_t>(e)].local);
      if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  std::vector<std::vector<std::size_t>> groups(blocks);
  for (std::size_t k = 0; k < blocks; ++k)
    if (sys.touched[k])
      groups[static_cast<std::size_t>(find(static_cast<std::int32_t>(k)))].push_back(k);
  return groups;
}

}  // namespace

void StateSystem::remove_rigid_parts(const ParticleStore& p) {
  for (const auto& g : touched_groups(*this)) {
    if (g.empty()) continue;
    // Each strain's forces over the group, less their translation and rotation (the null space of
    // J W⁻¹ Jᵀ: central pairs change neither the net force nor the net moment).
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto k : g)
      for (int a = 0; a < dim; ++a)
        centre[a] += p.reference_position[a][static_cast<std::size_t>(particles[k])];
    centre /= static_cast<double>(g.size());
    const auto arm = [&](std::size_t k) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int a = 0; a < dim; ++a)
        x[a] = p.reference_position[a][static_cast<std::size_t>(particles[k])] - centre[a];
      return x;
    };
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    for (const auto k : g) {
      const Eigen::Vector3d x = arm(k);
      inertia += x.squaredNorm() * Eigen::Matrix3d::Identity() - x * x.transpose();
    }
    for (int q = 0; q < strains; ++q) {
      const auto force = [&](std::size_t k) {
        Eigen::Vector3d f = Eigen::Vector3d::Zero();
        for (int a = 0; a < dim; ++a) f[a] = rhs[static_cast<Eigen::Index>(k) * size + q * dim + a];
        return f;
      };
      Eigen::Vector3d net = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
      for (const auto k : g) net += force(k);
      net /= static_cast<double>(g.size());
      for (const auto k : g) moment += arm(k).cross(force(k) - net);
      Eigen::Vector3d spin = Eigen::Vector3d::Zero();
      if (dim == 2 && inertia(2, 2) > 0.0) spin[2] = moment[2] / inertia(2, 2);
      if (dim == 3) spin = inertia.ldlt().solve(moment);
      for (const auto k : g) {
        const Eigen::Vector3d rigid = net + spin.cross(arm(k));
        for (int a = 0; a < dim; ++a)
          rhs[static_cast<Eigen::Index>(k) * size + q * dim + a] -= rigid[a];
      }
    }
  }
}

}  // namespace dhpd::state_interface_detail
