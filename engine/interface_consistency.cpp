// Consistent level interfaces: per-bond stiffness factors from a minimum-change solve (docs/
// theory.md §4), by a matrix-free conjugate gradient with block-Jacobi preconditioning.
#include "engine/interface_consistency.hpp"

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

/// The region as a membership test (every particle when it is empty).
struct Region {
  const std::vector<std::int32_t>& list;
  bool all;
  bool has(std::int32_t i) const { return all || std::binary_search(list.begin(), list.end(), i); }
};

/// Horizon tests on the reference configuration, cached per particle.
class HorizonTests {
 public:
  HorizonTests(const BondList& b, const DualList& d, const ParticleStore& p)
      : b_(b), d_(d), p_(p) {}

  bool complete(std::int32_t i) {
    const auto it = complete_.find(i);
    if (it != complete_.end()) return it->second;
    const auto u = static_cast<std::size_t>(i);
    double m[3] = {0, 0, 0}, v = 0.0;
    for (auto k = b_.begin(u); k < b_.end(u); ++k) {
      const auto j = static_cast<std::size_t>(b_.neighbor[k]);
      const double w = b_.weight[k] * p_.volume[j];
      v += w;
      for (int a = 0; a < p_.dim(); ++a)
        m[a] += w * (p_.reference_position[a][j] - p_.reference_position[a][u]);
    }
    const double first = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    return complete_[i] = v > 0.0 && first < kCompleteHorizonMoment * v * p_.horizon[u];
  }

  /// Calls f(partner) for every own neighbour and every owner of a bond on i.
  template <class F>
  void each_partner(std::size_t i, F&& f) const {
    for (auto k = b_.begin(i); k < b_.end(i); ++k) f(b_.neighbor[k]);
    for (auto e = d_.begin(i); e < d_.end(i); ++e) f(b_.owner[d_.bond[e]]);
  }

  /// Near a horizon jump, complete, and every partner complete.
  bool constrained(std::int32_t i) {
    const auto u = static_cast<std::size_t>(i);
    bool jump = false, partners_complete = true;
    each_partner(u, [&](std::int32_t j) {
      const double a = p_.horizon[u], c = p_.horizon[static_cast<std::size_t>(j)];
      jump = jump || std::max(a, c) >= kHorizonJumpRatio * std::min(a, c);
    });
    if (!jump || !complete(i)) return false;
    each_partner(u, [&](std::int32_t j) { partners_complete = partners_complete && complete(j); });
    return partners_complete;
  }

 private:
  const BondList& b_;
  const DualList& d_;
  const ParticleStore& p_;
  std::unordered_map<std::int32_t, bool> complete_;
};

/// One unknown: bond b between constrained particles li (owner) and lj, a_b = (V_j N, −V_i N).
struct Unknown {
  std::int64_t bond;
  std::int32_t li, lj;
  double K, vi, vj;
  Moment N;
};

}  // namespace

std::vector<double> third_moment(const BondList& b, const DualList& d, const ParticleStore& p,
                                 const std::vector<double>& C, std::size_t i) {
  Moment t = Moment::Zero(components(p.dim()));
  for (auto k = b.begin(i); k < b.end(i); ++k) {
    const auto j = static_cast<std::size_t>(b.neighbor[k]);
    t += (C[i] * b.weight[k] * b.stiffness[k] * p.volume[j]) * moment_of(p, i, j);
  }
  for (auto e = d.begin(i); e < d.end(i); ++e) {
    const auto k = d.bond[e];
    const auto o = static_cast<std::size_t>(b.owner[k]);
    t += (C[o] * b.weight[k] * b.stiffness[k] * p.volume[o]) * moment_of(p, i, o);
  }
  return {t.data(), t.data() + t.size()};
}

namespace {

/// Tikhonov weight: the solve is (M + ε diag M) x = rhs, which keeps the factors bounded where a
/// particle's bonds cannot cancel part of its moment (that part stays as a residual).
constexpr double kRegularization = 1e-6;

/// y = (M + R) x with M = Σ_b K_b a_b a_bᵀ (block rows of c per constrained particle) and R the
/// regularization blocks ε (D_p + tr(D_p)/c I), D_p the diagonal blocks of M.
void apply(const std::vector<Unknown>& us, const std::vector<Block>& reg, const Eigen::VectorXd& x,
           Eigen::VectorXd& y, int c) {
  for (std::size_t k = 0; k < reg.size(); ++k) {
    const auto at = c * static_cast<Eigen::Index>(k);
    y.segment(at, c) = reg[k] * x.segment(at, c);
  }
  for (const auto& u : us) {
    const double s = u.N.dot(u.vj * x.segment(c * u.li, c) - u.vi * x.segment(c * u.lj, c));
    y.segment(c * u.li, c) += (u.K * u.vj * s) * u.N;
    y.segment(c * u.lj, c) -= (u.K * u.vi * s) * u.N;
  }
}

/// Solves M x = rhs by conjugate gradients with the inverse diagonal blocks as preconditioner.
int solve(const std::vector<Unknown>& us, const std::vector<Block>& diag,
          const std::vector<Block>& inv_diag, const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
          int c) {
  x.setZero(rhs.size());
  Eigen::VectorXd r = rhs, z(rhs.size()), q(rhs.size());
  auto precondition = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    for (std::size_t k = 0; k < inv_diag.size(); ++k)
      out.segment(c * static_cast<Eigen::Index>(k), c) =
          inv_diag[k] * in.segment(c * static_cast<Eigen::Index>(k), c);
  };
  precondition(r, z);
  Eigen::VectorXd dir = z;
  double rz = r.dot(z);
  const double stop = 1e-13 * rhs.norm();
  int it = 0;
  for (; it < 5000 && r.norm() > stop; ++it) {
    apply(us, diag, dir, q, c);
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

}  // namespace

InterfaceCorrection correct_level_interfaces(BondList& b, const DualList& d, const ParticleStore& p,
                                             const std::vector<double>& C,
                                             const std::vector<std::int32_t>& region) {
  InterfaceCorrection out;
  const Region in{region, region.empty()};
  const std::size_t n = in.all ? p.size() : region.size();
  auto particle = [&](std::size_t k) { return in.all ? static_cast<std::int32_t>(k) : region[k]; };
  for (std::size_t k = 0; k < n; ++k) {  // reset the factors inside the region
    const auto i = static_cast<std::size_t>(particle(k));
    for (auto e = b.begin(i); e < b.end(i); ++e)
      if (in.has(b.neighbor[e])) b.stiffness[e] = 1.0;
  }
  HorizonTests tests(b, d, p);
  std::unordered_map<std::int32_t, std::int32_t> local;
  std::vector<std::int32_t> constrained;
  for (std::size_t k = 0; k < n; ++k)
    if (tests.constrained(particle(k))) constrained.push_back(particle(k));
  for (std::size_t k = 0; k < constrained.size(); ++k)
    local[constrained[k]] = static_cast<std::int32_t>(k);
  // Unknowns: the bonds between constrained particles; particles without one drop out.
  const int c = components(p.dim());
  std::vector<Unknown> us;
  std::vector<int> touched(constrained.size(), 0);
  for (std::size_t k = 0; k < constrained.size(); ++k) {
    const auto i = static_cast<std::size_t>(constrained[k]);
    for (auto e = b.begin(i); e < b.end(i); ++e) {
      const auto it = local.find(b.neighbor[e]);
      if (it == local.end()) continue;
      const auto j = static_cast<std::size_t>(b.neighbor[e]);
      us.push_back({e, static_cast<std::int32_t>(k), it->second, C[i] * b.weight[e], p.volume[i],
                    p.volume[j], moment_of(p, i, j)});
      ++touched[k], ++touched[static_cast<std::size_t>(it->second)];
    }
  }
  if (us.empty()) return out;
  std::vector<Block> diag(constrained.size(), Block::Zero(c, c)), inv_diag(constrained.size());
  std::vector<Block> diag_of_m;
  for (const auto& u : us) {
    diag[static_cast<std::size_t>(u.li)] += (u.K * u.vj * u.vj) * u.N * u.N.transpose();
    diag[static_cast<std::size_t>(u.lj)] += (u.K * u.vi * u.vi) * u.N * u.N.transpose();
  }
  diag_of_m = diag;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(c * static_cast<Eigen::Index>(constrained.size()));
  double before = 0.0;
  for (std::size_t k = 0; k < constrained.size(); ++k) {
    const auto t = third_moment(b, d, p, C, static_cast<std::size_t>(constrained[k]));
    for (int a = 0; a < c; ++a) rhs(c * static_cast<Eigen::Index>(k) + a) = -t[a];
    before = std::max(before, rhs.segment(c * static_cast<Eigen::Index>(k), c).norm());
    // Particles without unknowns drop out (their x stays zero and is never used).
    auto& D = diag[k];
    D = kRegularization * (D + (D.trace() / c) * Block::Identity(c, c));  // now the R block
    inv_diag[k] = touched[k] ? Block((diag_of_m[k] + D).ldlt().solve(Block::Identity(c, c)))
                             : Block::Zero(c, c);
    if (!touched[k]) rhs.segment(c * static_cast<Eigen::Index>(k), c).setZero();
  }
  std::vector<double> volume(constrained.size());
  for (std::size_t k = 0; k < constrained.size(); ++k)
    volume[k] = p.volume[static_cast<std::size_t>(constrained[k])];
  remove_net_moment(rhs, components_of(us, constrained.size()), volume, touched, c);
  Eigen::VectorXd x;
  out.iterations = solve(us, diag, inv_diag, rhs, x, c);
  for (const auto& u : us) {
    const double solved = u.N.dot(u.vj * x.segment(c * u.li, c) - u.vi * x.segment(c * u.lj, c));
    // Where the bonds cannot cancel a moment with moderate factors, the factor is clipped: the
    // correction is then partial there, never a soft or negative bond.
    const double lambda = std::clamp(solved, kSmallestFactor - 1.0, kLargestFactor - 1.0);
    out.clipped += lambda != solved ? 1 : 0;
    b.stiffness[static_cast<std::size_t>(u.bond)] = 1.0 + lambda;
    out.smallest = std::min(out.smallest, 1.0 + lambda);
    out.largest = std::max(out.largest, 1.0 + lambda);
  }
  double after = 0.0;
  for (std::size_t k = 0; k < constrained.size(); ++k) {
    if (!touched[k]) continue;
    const auto t = third_moment(b, d, p, C, static_cast<std::size_t>(constrained[k]));
    after = std::max(after, Eigen::Map<const Eigen::VectorXd>(t.data(), c).norm());
  }
  out.particles = constrained.size();
  out.bonds = us.size();
  out.residual = before > 0.0 ? after / before : 0.0;
  return out;
}

}  // namespace dhpd
