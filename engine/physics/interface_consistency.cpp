// Consistent level interfaces: per-bond stiffness factors from a minimum-change solve
// (docs/theory.md §14), by a matrix-free conjugate gradient with block-Jacobi preconditioning.
#include "engine/physics/interface_consistency.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace dhpd {

namespace {

constexpr int kMaxComponents = 10;
using Block =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxComponents, kMaxComponents>;
using Moment = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxComponents, 1>;

int components(int dim) {
  return dim == 1 ? 1 : (dim == 2 ? 4 : 10);
}

/// n⊗n⊗n of the unit vector from particle i to j (reference positions), independent components.
Moment moment_of(const ParticleStore& p, std::size_t i, std::size_t j) {
  const int d = p.dim();
  double n[3] = {0, 0, 0}, len2 = 0.0;
  for (int a = 0; a < d; ++a) {
    n[a] = p.reference_position[a][j] - p.reference_position[a][i];
    len2 += n[a] * n[a];
  }
  const double inv = 1.0 / std::sqrt(len2);
  for (int a = 0; a < d; ++a) n[a] *= inv;
  const double x = n[0], y = n[1], z = n[2];
  Moment m(components(d));
  if (d == 1) {
    m << x * x * x;
  } else if (d == 2) {
    m << x * x * x, x * x * y, x * y * y, y * y * y;
  } else {
    m << x * x * x, y * y * y, z * z * z, x * x * y, x * x * z, x * y * y, y * y * z, x * z * z,
        y * z * z, x * y * z;
  }
  return m;
}

/// The region as a membership test (every particle when it is empty), one flag per particle.
class Region {
 public:
  Region(const std::vector<std::int32_t>& list, std::size_t particles) : all_(list.empty()) {
    if (all_) return;
    member_.assign(particles, 0);
    for (const auto i : list) member_[static_cast<std::size_t>(i)] = 1;
  }
  bool all() const { return all_; }
  bool has(std::int32_t i) const { return all_ || member_[static_cast<std::size_t>(i)] != 0; }

 private:
  bool all_;
  std::vector<std::uint8_t> member_;
};

/// Horizon tests on the reference configuration, cached per particle.
class HorizonTests {
 public:
  HorizonTests(const BondRows& b, const ParticleStore& p, PartialVolume rule)
      : b_(b), p_(p), rule_(rule) {}

  bool complete(std::int32_t i) {
    if (complete_.empty()) complete_.assign(p_.size(), -1);
    if (complete_[static_cast<std::size_t>(i)] >= 0)
      return complete_[static_cast<std::size_t>(i)] == 1;
    const auto u = static_cast<std::size_t>(i);
    double m[3] = {0, 0, 0}, v = 0.0;
    for_each_own_bond(b_, u, [&](std::int64_t k, std::size_t j) {
      const double w = bond_weight(p_, rule_, u, j, b_.length(k)) * p_.volume[j];
      v += w;
      for (int a = 0; a < p_.dim(); ++a)
        m[a] += w * (p_.reference_position[a][j] - p_.reference_position[a][u]);
    });
    const double first = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const bool complete = v > 0.0 && first < complete_horizon_moment(p_.dim()) * v * p_.horizon[u];
    complete_[u] = complete ? 1 : 0;
    return complete;
  }

  /// Calls f(partner) for every particle i shares a bond with (own or dual).
  template <class F>
  void each_partner(std::size_t i, F&& f) const {
    for (auto k = b_.begin(i); k < b_.end(i); ++k) f(b_.other[k]);
  }

  /// A bond (own or dual) to a particle whose horizon differs by kHorizonJumpRatio or more
  /// (cached: constrained() asks it of every partner of every particle).
  bool at_jump(std::size_t i) {
    if (jump_.empty()) jump_.assign(p_.size(), -1);
    if (jump_[i] >= 0) return jump_[i] == 1;
    bool jump = false;
    each_partner(i, [&](std::int32_t j) {
      const double a = p_.horizon[i], c = p_.horizon[static_cast<std::size_t>(j)];
      jump = jump || std::max(a, c) >= kHorizonJumpRatio * std::min(a, c);
    });
    jump_[i] = jump ? 1 : 0;
    return jump;
  }

  /// At a jump or bonded to a particle at one (so the correction has bonds on every side),
  /// complete, and every partner complete.
  bool constrained(std::int32_t i) {
    const auto u = static_cast<std::size_t>(i);
    bool near = at_jump(u);
    if (!near)
      each_partner(u, [&](std::int32_t j) { near = near || at_jump(static_cast<std::size_t>(j)); });
    if (!near || !complete(i)) return false;
    bool partners_complete = true;
    each_partner(u, [&](std::int32_t j) { partners_complete = partners_complete && complete(j); });
    return partners_complete;
  }

 private:
  const BondRows& b_;
  const ParticleStore& p_;
  PartialVolume rule_;
  std::vector<std::int8_t> complete_;  ///< per particle: −1 not asked yet, else complete()
  std::vector<std::int8_t> jump_;      ///< per particle: −1 not asked yet, else at_jump's answer
};

/// One unknown: bond b between constrained particles li (owner) and lj, a_b = (V_j N, −V_i N).
struct Unknown {
  std::int64_t bond;
  std::int32_t li, lj;
  double K, vi, vj;
  Moment N;
};

}  // namespace

std::vector<double> third_moment(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                                 const std::vector<double>& C, std::size_t i) {
  Moment t = Moment::Zero(components(p.dim()));
  for (auto k = b.begin(i); k < b.end(i); ++k) {
    const auto j = static_cast<std::size_t>(b.other[k]);
    const double length = b.length(k);
    double K = 0.0;
    if (b.has_own(k)) K += C[i] * bond_weight(p, rule, i, j, length) * b.own_factor(k);
    if (b.has_dual(k)) {
      const double factor =
          b.factor.empty() ? 1.0 : b.own_factor(b.find(j, static_cast<std::int32_t>(i)));
      K += C[j] * bond_weight(p, rule, j, i, length) * factor;
    }
    t += (K * p.volume[j]) * moment_of(p, i, j);
  }
  return {t.data(), t.data() + t.size()};
}

namespace {

/// The conjugate-gradient solve of (M + R) x = rhs, with C components per particle fixed at
/// compile time: M = Σ_b K_b a_b a_bᵀ, R the regularization blocks γ (D_p + tr(D_p)/C I) with D_p
/// the diagonal blocks of M, preconditioned by the inverses of D_p + R_p.
template <int C>
struct BlockSolver {
  using Vec = Eigen::Matrix<double, C, 1>;
  using Mat = Eigen::Matrix<double, C, C>;
  /// One unknown as the products apply() needs, in fixed-size storage (the Unknown's moment is
  /// sized at run time): 8 + 3·8 + 8·C bytes instead of Unknown's 128.
  struct Term {
    std::int32_t li, lj;
    double vi, vj, K;
    Vec N;
  };
  std::vector<Term> terms;
  std::vector<Mat> reg, inv;

  BlockSolver(const std::vector<Unknown>& unknowns, const std::vector<Block>& diag,
              const std::vector<int>& touched, double gamma)
      : reg(diag.size()), inv(diag.size()) {
    terms.reserve(unknowns.size());
    for (const auto& u : unknowns)
      terms.push_back(Term{u.li, u.lj, u.vi, u.vj, u.K, u.N.template head<C>()});
    for (std::size_t k = 0; k < diag.size(); ++k) {
      const Mat D = diag[k];
      reg[k] = gamma * (D + (D.trace() / C) * Mat::Identity());
      inv[k] = touched[k] ? Mat((D + reg[k]).ldlt().solve(Mat::Identity())) : Mat::Zero();
    }
  }

  static auto at(Eigen::VectorXd& v, std::int32_t k) { return v.template segment<C>(C * k); }
  static auto at(const Eigen::VectorXd& v, std::int32_t k) { return v.template segment<C>(C * k); }

  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    for (std::size_t k = 0; k < reg.size(); ++k)
      at(y, static_cast<std::int32_t>(k)) = reg[k] * at(x, static_cast<std::int32_t>(k));
    for (const auto& t : terms) {
      const double s = t.N.dot(t.vj * at(x, t.li) - t.vi * at(x, t.lj));
      at(y, t.li) += (t.K * t.vj * s) * t.N;
      at(y, t.lj) -= (t.K * t.vi * s) * t.N;
    }
  }

  void precondition(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
    for (std::size_t k = 0; k < inv.size(); ++k)
      at(out, static_cast<std::int32_t>(k)) = inv[k] * at(in, static_cast<std::int32_t>(k));
  }

  int solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
    x.setZero(rhs.size());
    Eigen::VectorXd r = rhs, z(rhs.size()), q(rhs.size());
    precondition(r, z);
    Eigen::VectorXd dir = z;
    double rz = r.dot(z);
    const double stop = 1e-3 * rhs.norm();  // the moments to 1e-3 of what they were
    int it = 0;
    for (; it < 2000 && r.norm() > stop; ++it) {
      apply(dir, q);
      const double alpha = rz / dir.dot(q);
      x += alpha * dir;
      r -= alpha * q;
      precondition(r, z);
      const double rz_next = r.dot(z);
      dir = z + (rz_next / rz) * dir;
      rz = rz_next;
    }
    return it;
  }
};

/// Connected components of the constrained particles through the unknowns (union-find).
std::vector<std::int32_t> components_of(const std::vector<Unknown>& us, std::size_t n) {
  std::vector<std::int32_t> root(n);
  for (std::size_t k = 0; k < n; ++k) root[k] = static_cast<std::int32_t>(k);
  auto find = [&](std::int32_t k) {
    while (root[static_cast<std::size_t>(k)] != k)
      k = root[static_cast<std::size_t>(k)] =
          root[static_cast<std::size_t>(root[static_cast<std::size_t>(k)])];
    return k;
  };
  for (const auto& u : us) {
    const auto a = find(u.li), b = find(u.lj);
    if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  for (std::size_t k = 0; k < n; ++k) root[k] = find(static_cast<std::int32_t>(k));
  return root;
}

/// Within each component no factor can change Σ V_p T_p (every bond adds V_i V_j K N − V_j V_i K N
/// to it): that part of the right-hand side is left as a residual spread as V_p ȳ, which keeps
/// the system consistent (x_p = V_p y is its null space).
void remove_net_moment(Eigen::VectorXd& rhs, const std::vector<std::int32_t>& component,
                       const std::vector<double>& volume, const std::vector<int>& touched, int c) {
  std::unordered_map<std::int32_t, std::pair<Eigen::VectorXd, double>> sums;
  for (std::size_t k = 0; k < component.size(); ++k) {
    if (!touched[k]) continue;
    auto& s = sums.try_emplace(component[k], Eigen::VectorXd::Zero(c), 0.0).first->second;
    s.first += volume[k] * rhs.segment(c * static_cast<Eigen::Index>(k), c);
    s.second += volume[k] * volume[k];
  }
  for (std::size_t k = 0; k < component.size(); ++k) {
    if (!touched[k]) continue;
    const auto& s = sums.at(component[k]);
    rhs.segment(c * static_cast<Eigen::Index>(k), c) -= (volume[k] / s.second) * s.first;
  }
}

/// The system of one correction: unknown bonds, constrained particles and their moments.
struct System {
  int c = 0;
  std::vector<std::int32_t> constrained;
  std::vector<Unknown> us;
  std::vector<int> touched;  ///< unknowns per constrained particle
  std::vector<Block> diag;   ///< diagonal blocks of M
  Eigen::VectorXd rhs;       ///< −T, less the part no factor can change
  double before = 0.0;       ///< largest |T| before
};

System assemble(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                const std::vector<double>& C, std::vector<std::int32_t> constrained) {
  System sys;
  sys.c = components(p.dim());
  const int c = sys.c;
  sys.constrained = std::move(constrained);
  const std::size_t n = sys.constrained.size();
  std::vector<std::int32_t> local(p.size(), -1);  // particle -> unknown block
  for (std::size_t k = 0; k < n; ++k)
    local[static_cast<std::size_t>(sys.constrained[k])] = static_cast<std::int32_t>(k);
  sys.touched.assign(n, 0);
  sys.diag.assign(n, Block::Zero(c, c));
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(sys.constrained[k]);
    for_each_own_bond(b, i, [&](std::int64_t e, std::size_t j) {
      const std::int32_t other = local[j];
      if (other < 0) return;
      const Unknown u{e,
                      static_cast<std::int32_t>(k),
                      other,
                      C[i] * bond_weight(p, rule, i, j, b.length(e)),
                      p.volume[i],
                      p.volume[j],
                      moment_of(p, i, j)};
      sys.diag[k] += (u.K * u.vj * u.vj) * u.N * u.N.transpose();
      sys.diag[static_cast<std::size_t>(u.lj)] += (u.K * u.vi * u.vi) * u.N * u.N.transpose();
      ++sys.touched[k], ++sys.touched[static_cast<std::size_t>(other)];
      sys.us.push_back(u);
    });
  }
  sys.rhs = Eigen::VectorXd::Zero(c * static_cast<Eigen::Index>(n));
  std::vector<double> volume(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(sys.constrained[k]);
    const auto t = third_moment(b, p, rule, C, i);
    volume[k] = p.volume[i];
    for (int a = 0; a < c; ++a) sys.rhs(c * static_cast<Eigen::Index>(k) + a) = -t[a];
    sys.before = std::max(sys.before, sys.rhs.segment(c * static_cast<Eigen::Index>(k), c).norm());
    // Particles without unknowns drop out (their x stays zero and is never used).
    if (!sys.touched[k]) sys.rhs.segment(c * static_cast<Eigen::Index>(k), c).setZero();
  }
  remove_net_moment(sys.rhs, components_of(sys.us, n), volume, sys.touched, c);
  return sys;
}

/// λ_b of every unknown from a solve with Tikhonov weight `gamma`.
template <int C>
std::vector<double> factors_of(const System& sys, double gamma, int& iterations) {
  const BlockSolver<C> solver(sys.us, sys.diag, sys.touched, gamma);
  Eigen::VectorXd x;
  iterations += solver.solve(sys.rhs, x);
  std::vector<double> lambda;
  lambda.reserve(solver.terms.size());
  for (const auto& t : solver.terms)
    lambda.push_back(
        t.N.dot(t.vj * x.template segment<C>(C * t.li) - t.vi * x.template segment<C>(C * t.lj)));
  return lambda;
}

std::vector<double> factors_with(const System& sys, double gamma, int& iterations) {
  switch (sys.c) {
    case 1:
      return factors_of<1>(sys, gamma, iterations);
    case 4:
      return factors_of<4>(sys, gamma, iterations);
    default:
      return factors_of<10>(sys, gamma, iterations);
  }
}

}  // namespace

InterfaceCorrection correct_level_interfaces(BondRows& b, const ParticleStore& p,
                                             PartialVolume rule, const std::vector<double>& C,
                                             const std::vector<std::int32_t>& region) {
  InterfaceCorrection out;
  const Region in(region, p.size());
  const std::size_t n = in.all() ? p.size() : region.size();
  auto particle = [&](std::size_t k) {
    return in.all() ? static_cast<std::int32_t>(k) : region[k];
  };
  if (!b.factor.empty())
    for (std::size_t k = 0; k < n; ++k) {  // reset the factors inside the region
      const auto i = static_cast<std::size_t>(particle(k));
      for_each_own_bond(b, i, [&](std::int64_t e, std::size_t j) {
        if (in.has(static_cast<std::int32_t>(j))) b.factor[e] = 1.0f;
      });
    }
  HorizonTests tests(b, p, rule);
  std::vector<std::int32_t> constrained;
  for (std::size_t k = 0; k < n; ++k)
    if (tests.constrained(particle(k))) constrained.push_back(particle(k));
  const System sys = assemble(b, p, rule, C, std::move(constrained));
  if (sys.us.empty()) return out;
  // The weakest damping whose factors stay within bounds but for a few (kClippedShare): where
  // the bonds cannot cancel a moment with moderate factors, a stronger Tikhonov weight leaves part
  // of it (never a soft or negative bond); the remaining few are clipped.
  if (b.factor.empty()) b.factor.assign(static_cast<std::size_t>(b.rows.arena), 1.0f);
  std::vector<double> lambda;
  for (const double gamma : {1e-3, 1e-1}) {
    lambda = factors_with(sys, gamma, out.iterations);
    const auto outside = std::count_if(lambda.begin(), lambda.end(), [](double l) {
      return l < kSmallestFactor - 1.0 || l > kLargestFactor - 1.0;
    });
    if (static_cast<double>(outside) <= kClippedShare * static_cast<double>(lambda.size())) break;
  }
  for (std::size_t k = 0; k < sys.us.size(); ++k) {
    const double clipped = std::clamp(lambda[k], kSmallestFactor - 1.0, kLargestFactor - 1.0);
    out.clipped += clipped != lambda[k] ? 1 : 0;
    b.factor[static_cast<std::size_t>(sys.us[k].bond)] = static_cast<float>(1.0 + clipped);
    out.smallest = std::min(out.smallest, 1.0 + clipped);
    out.largest = std::max(out.largest, 1.0 + clipped);
  }
  double after = 0.0;
  for (std::size_t k = 0; k < sys.constrained.size(); ++k) {
    if (!sys.touched[k]) continue;
    const auto t = third_moment(b, p, rule, C, static_cast<std::size_t>(sys.constrained[k]));
    after = std::max(after, Eigen::Map<const Eigen::VectorXd>(t.data(), sys.c).norm());
  }
  out.particles = sys.constrained.size();
  out.bonds = sys.us.size();
  out.residual = sys.before > 0.0 ? after / sys.before : 0.0;
  return out;
}

}  // namespace dhpd
