// Consistent level interfaces: per-bond stiffness factors from a minimum-change solve
// (docs/theory.md §14), by a matrix-free conjugate gradient with block-Jacobi preconditioning
// (engine/physics/interface_system.hpp).
#include "engine/physics/interface_consistency.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <unordered_map>

#include "engine/physics/interface_system.hpp"

namespace dhpd {

namespace {

using namespace interface_detail;

/// Calls f(std::integral_constant<int, C>{}) with C the independent components of n⊗n⊗n in the
/// dimension (1, 4, 10): the one place the block size is chosen, once per correction.
template <class F>
decltype(auto) with_components(int dim, F&& f) {
  if (dim == 1) return f(std::integral_constant<int, 1>{});
  if (dim == 2) return f(std::integral_constant<int, 4>{});
  return f(std::integral_constant<int, 10>{});
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

}  // namespace

std::vector<double> third_moment(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                                 const std::vector<double>& C, std::size_t i) {
  return with_components(p.dim(), [&](auto c) {
    const auto t = third_moment_of<c()>(b, p, rule, C, i);
    return std::vector<double>(t.data(), t.data() + t.size());
  });
}

namespace {

/// Connected components of the constrained particles through the unknowns (union-find).
template <int C>
std::vector<std::int32_t> components_of(const std::vector<Term<C>>& terms, std::size_t n) {
  std::vector<std::int32_t> root(n);
  for (std::size_t k = 0; k < n; ++k) root[k] = static_cast<std::int32_t>(k);
  auto find = [&](std::int32_t k) {
    while (root[static_cast<std::size_t>(k)] != k)
      k = root[static_cast<std::size_t>(k)] =
          root[static_cast<std::size_t>(root[static_cast<std::size_t>(k)])];
    return k;
  };
  for (const auto& t : terms) {
    const auto a = find(t.li), b = find(t.lj);
    if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  for (std::size_t k = 0; k < n; ++k) root[k] = find(static_cast<std::int32_t>(k));
  return root;
}

/// Within each component no factor can change Σ V_p T_p (every bond adds V_i V_j K N − V_j V_i K N
/// to it): that part of the right-hand side is left as a residual spread as V_p ȳ, which keeps
/// the system consistent (x_p = V_p y is its null space).
template <int C>
void remove_net_moment(System<C>& sys, const std::vector<double>& volume) {
  const auto component = components_of(sys.terms, sys.blocks());
  std::unordered_map<std::int32_t, std::pair<Vec<C>, double>> sums;
  for (std::size_t k = 0; k < component.size(); ++k) {
    if (!sys.touched(k)) continue;
    auto& s = sums.try_emplace(component[k], Vec<C>::Zero(), 0.0).first->second;
    s.first += volume[k] * sys.rhs.template segment<C>(C * static_cast<Eigen::Index>(k));
    s.second += volume[k] * volume[k];
  }
  for (std::size_t k = 0; k < component.size(); ++k) {
    if (!sys.touched(k)) continue;
    const auto& s = sums.at(component[k]);
    sys.rhs.template segment<C>(C * static_cast<Eigen::Index>(k)) -=
        (volume[k] / s.second) * s.first;
  }
}

/// The unknowns: every own bond of a constrained particle to another constrained particle, in
/// row order of the owners (counted, then written in parallel at their places).
template <int C>
void collect_terms(System<C>& sys, const BondRows& b, const ParticleStore& p, PartialVolume rule,
                   const std::vector<double>& micromodulus) {
  const auto n = static_cast<std::int64_t>(sys.blocks());
  std::vector<std::int32_t> local(p.size(), -1);  // particle -> block
  for (std::int64_t k = 0; k < n; ++k) local[static_cast<std::size_t>(sys.constrained[k])] = k;
  std::vector<std::int64_t> first(static_cast<std::size_t>(n) + 1, 0);
  const bool parallel = n >= kParallelMinParticles / 16;  // each block has tens of bonds
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t k = 0; k < n; ++k)
    for_each_own_bond(b, static_cast<std::size_t>(sys.constrained[k]),
                      [&](std::int64_t, std::size_t j) { first[k + 1] += local[j] >= 0 ? 1 : 0; });
  for (std::int64_t k = 0; k < n; ++k) first[k + 1] += first[k];
  sys.terms.resize(static_cast<std::size_t>(first[n]));
  sys.bond.resize(sys.terms.size());
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(sys.constrained[k]);
    auto e = first[k];
    for_each_own_bond(b, i, [&](std::int64_t bond, std::size_t j) {
      if (local[j] < 0) return;
      const double K = micromodulus[i] * bond_weight(p, rule, i, j, b.length(bond));
      const double vi = p.volume[i], vj = p.volume[j];
      sys.terms[e] = Term<C>{static_cast<std::int32_t>(k), local[j], vi, vj, K * vi, K * vj,
                             moment_of<C>(p, i, j)};
      sys.bond[e++] = bond;
    });
  }
}

template <int C>
System<C> assemble(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                   const std::vector<double>& micromodulus, std::vector<std::int32_t> constrained) {
  System<C> sys;
  sys.constrained = std::move(constrained);
  collect_terms(sys, b, p, rule, micromodulus);
  diagonal_blocks(sys);
  const auto n = static_cast<std::int64_t>(sys.blocks());
  sys.rhs = Eigen::VectorXd::Zero(C * n);
  std::vector<double> volume(static_cast<std::size_t>(n)), size(static_cast<std::size_t>(n));
  sys.moment.resize(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static) if (sys.parallel())
  for (std::int64_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(sys.constrained[k]);
    const Vec<C> t = third_moment_of<C>(b, p, rule, micromodulus, i);
    sys.moment[k] = t;
    volume[k] = p.volume[i];
    size[k] = t.norm();
    // Particles without unknowns drop out (their x stays zero and is never used).
    if (sys.touched(k)) sys.rhs.template segment<C>(C * k) = -t;
  }
  for (const double s : size) sys.before = std::max(sys.before, s);
  remove_net_moment(sys, volume);
  return sys;
}

/// Solves for the factors and writes them: the weakest damping whose factors stay within bounds
/// but for a few (kClippedShare). Where the bonds cannot cancel a moment with moderate factors, a
/// stronger Tikhonov weight leaves part of it (never a soft or negative bond); the remaining few
/// are clipped.
template <int C>
void solve_and_write(const System<C>& sys, BondRows& b, InterfaceCorrection& out) {
  if (b.factor.empty()) b.factor.assign(static_cast<std::size_t>(b.rows.arena), 1.0f);
  const auto solve = [&](double gamma, std::vector<double>& lambda) {
    BlockSolver<C> solver(sys, gamma);
    Eigen::VectorXd x;
    const int iterations = solver.solve(x);
    lambda = solver.factors(x);
    return iterations;
  };
  const auto lambda =
      least_damped_changes({1e-3, 1e-1}, kSmallestFactor, kLargestFactor, solve, out.iterations);
  for (std::size_t e = 0; e < sys.terms.size(); ++e)
    b.factor[static_cast<std::size_t>(sys.bond[e])] =
        static_cast<float>(clipped_factor(lambda[e], kSmallestFactor, kLargestFactor, out));
}

template <int C>
void correct(BondRows& b, const ParticleStore& p, PartialVolume rule,
             const std::vector<double>& micromodulus, std::vector<std::int32_t> constrained,
             InterfaceCorrection& out) {
  const System<C> sys = assemble<C>(b, p, rule, micromodulus, std::move(constrained));
  if (sys.terms.empty()) return;
  solve_and_write(sys, b, out);
  // T after: T before plus what each solved bond's new factor adds at its two ends (the bonds
  // outside the system kept their factors), K (φ − 1) V_other n⊗n⊗n, n odd in the direction.
  std::vector<Vec<C>> after = sys.moment;
  for (std::size_t e = 0; e < sys.terms.size(); ++e) {
    const auto& t = sys.terms[e];
    const double change =
        static_cast<double>(b.factor[static_cast<std::size_t>(sys.bond[e])]) - 1.0;
    after[static_cast<std::size_t>(t.li)] += (t.kvj * change) * t.N;
    after[static_cast<std::size_t>(t.lj)] -= (t.kvi * change) * t.N;
  }
  out.particles = sys.blocks();
  out.bonds = sys.terms.size();
  double largest = 0.0;
  for (std::size_t k = 0; k < after.size(); ++k)
    if (sys.touched(k)) largest = std::max(largest, after[k].norm());
  out.residual = sys.before > 0.0 ? largest / sys.before : 0.0;
}

}  // namespace

std::vector<std::int32_t> reset_interface_region(BondRows& b, const ParticleStore& p,
                                                 PartialVolume rule,
                                                 const std::vector<std::int32_t>& region) {
  const Region in(region, p.size());
  const std::size_t n = in.all() ? p.size() : region.size();
  auto particle = [&](std::size_t k) {
    return in.all() ? static_cast<std::int32_t>(k) : region[k];
  };
  for (auto* factors : {&b.factor, &b.dilatation_factor}) {
    if (factors->empty()) continue;
    for (std::size_t k = 0; k < n; ++k) {  // reset the factors inside the region
      const auto i = static_cast<std::size_t>(particle(k));
      for_each_own_bond(b, i, [&](std::int64_t e, std::size_t j) {
        if (in.has(static_cast<std::int32_t>(j))) (*factors)[static_cast<std::size_t>(e)] = 1.0f;
      });
    }
  }
  HorizonTests tests(b, p, rule);
  std::vector<std::int32_t> constrained;
  for (std::size_t k = 0; k < n; ++k)
    if (tests.constrained(particle(k))) constrained.push_back(particle(k));
  return constrained;
}

InterfaceCorrection correct_level_interfaces(BondRows& b, const ParticleStore& p,
                                             PartialVolume rule, const std::vector<double>& C,
                                             const std::vector<std::int32_t>& region) {
  InterfaceCorrection out;
  auto constrained = reset_interface_region(b, p, rule, region);
  with_components(p.dim(),
                  [&](auto c) { correct<c()>(b, p, rule, C, std::move(constrained), out); });
  return out;
}

}  // namespace dhpd
