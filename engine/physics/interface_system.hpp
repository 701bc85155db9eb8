// The linear system of the consistent-interface correction and its conjugate-gradient solve
// (docs/theory.md §14), in fixed-size blocks of C components (1, 4 or 10). The per-particle parts
// of the assembly (the unknowns of each owner, the moments T) run in parallel, each written in
// its own place; the operator runs on one thread, in term order. A gather per block in parallel
// gave the same bits but no gain on two cores (0.47–0.50 s against 0.51 s of solves on
// Kalthoff–Winkler 2D adaptive: about 150 fork-joins per event for a few milliseconds of work).
#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/conjugate_gradient.hpp"

namespace dhpd::interface_detail {

template <int C>
using Vec = Eigen::Matrix<double, C, 1>;
template <int C>
using Mat = Eigen::Matrix<double, C, C>;

/// Below this many unknowns (bonds) a pass runs on one thread: the team's fork and join would
/// cost more than the work.
inline constexpr std::int64_t kParallelMinTerms = 8192;

/// n⊗n⊗n of the unit vector from particle i to j (reference positions), independent components.
template <int C>
Vec<C> moment_of(const ParticleStore& p, std::size_t i, std::size_t j) {
  const int d = p.dim();
  double n[3] = {0, 0, 0}, len2 = 0.0;
  for (int a = 0; a < d; ++a) {
    n[a] = p.reference_position[a][j] - p.reference_position[a][i];
    len2 += n[a] * n[a];
  }
  const double inv = 1.0 / std::sqrt(len2);
  for (int a = 0; a < d; ++a) n[a] *= inv;
  const double x = n[0], y = n[1], z = n[2];
  Vec<C> m;
  if constexpr (C == 1) {
    m << x * x * x;
  } else if constexpr (C == 4) {
    m << x * x * x, x * x * y, x * y * y, y * y * y;
  } else {
    m << x * x * x, y * y * y, z * z * z, x * x * y, x * x * z, x * y * y, y * y * z, x * z * z,
        y * z * z, x * y * z;
  }
  return m;
}

/// T_i = Σ_j (K_i→j + K_j→i) V_j n⊗n⊗n over i's row (own and dual bonds, current factors).
template <int C>
Vec<C> third_moment_of(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                       const std::vector<double>& micromodulus, std::size_t i) {
  Vec<C> t = Vec<C>::Zero();
  for (auto k = b.begin(i); k < b.end(i); ++k) {
    const auto j = static_cast<std::size_t>(b.other[k]);
    const double length = b.length(k);
    double K = 0.0;
    if (b.has_own(k)) K += micromodulus[i] * bond_weight(p, rule, i, j, length) * b.own_factor(k);
    if (b.has_dual(k)) {
      const double factor =
          b.factor.empty() ? 1.0 : b.own_factor(b.find(j, static_cast<std::int32_t>(i)));
      K += micromodulus[j] * bond_weight(p, rule, j, i, length) * factor;
    }
    t += (K * p.volume[j]) * moment_of<C>(p, i, j);
  }
  return t;
}

/// One unknown: bond `bond` between constrained particles li (owner) and lj with
/// a_b = (V_j N, −V_i N) and weight K; kvi = K V_i, kvj = K V_j.
template <int C>
struct Term {
  std::int32_t li, lj;
  double vi, vj, kvi, kvj;
  Vec<C> N;
};

/// The system of one correction: (M + R) x = rhs over the constrained particles' blocks, with
/// M = Σ_b K_b a_b a_bᵀ and R the regularisation chosen by the solve.
template <int C>
struct System {
  std::vector<std::int32_t> constrained;
  std::vector<Term<C>> terms;
  std::vector<std::int64_t> bond;      ///< per term: its entry in the rows
  std::vector<std::int32_t> incident;  ///< per block: how many terms it is an end of
  std::vector<Mat<C>> diag;            ///< diagonal blocks of M
  Eigen::VectorXd rhs;                 ///< −T, less the part no factor can change
  std::vector<Vec<C>> moment;          ///< per block: T before the solve
  double before = 0.0;                 ///< largest |T| before
  std::size_t blocks() const { return constrained.size(); }
  bool touched(std::size_t k) const { return incident[k] > 0; }
  bool parallel() const { return static_cast<std::int64_t>(terms.size()) >= kParallelMinTerms; }
};

/// The diagonal blocks of M (summed in term order) and how many terms each block is an end of.
template <int C>
void diagonal_blocks(System<C>& sys) {
  sys.incident.assign(sys.blocks(), 0);
  sys.diag.assign(sys.blocks(), Mat<C>::Zero());
  for (const auto& t : sys.terms) {
    sys.diag[t.li] += (t.kvj * t.vj) * t.N * t.N.transpose();
    sys.diag[t.lj] += (t.kvi * t.vi) * t.N * t.N.transpose();
    ++sys.incident[t.li], ++sys.incident[t.lj];
  }
}

/// The preconditioned conjugate-gradient solve of (M + R) x = rhs, R the regularisation blocks
/// γ (D_p + tr(D_p)/C I), D_p the diagonal blocks of M, preconditioned by (D_p + R_p)⁻¹.
template <int C>
class BlockSolver {
 public:
  BlockSolver(const System<C>& sys, double gamma)
      : sys_(sys), reg_(sys.blocks()), inv_(sys.blocks()) {
    for (std::size_t k = 0; k < sys.blocks(); ++k) {
      const Mat<C>& D = sys.diag[k];
      reg_[k] = gamma * (D + (D.trace() / C) * Mat<C>::Identity());
      inv_[k] =
          sys.touched(k) ? Mat<C>((D + reg_[k]).ldlt().solve(Mat<C>::Identity())) : Mat<C>::Zero();
    }
  }

  /// λ_b = a_bᵀ x of every term.
  std::vector<double> factors(const Eigen::VectorXd& x) const {
    std::vector<double> lambda(sys_.terms.size());
    const auto n = static_cast<std::int64_t>(lambda.size());
#pragma omp parallel for schedule(static) if (sys_.parallel())
    for (std::int64_t e = 0; e < n; ++e) lambda[e] = strain_of(sys_.terms[e], x);
    return lambda;
  }

  /// The moments to 10⁻³ of what they were.
  int solve(Eigen::VectorXd& x) const {
    return preconditioned_cg(
        sys_.rhs, x, [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { apply(in, out); },
        [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { precondition(in, out); });
  }

 private:
  static auto at(Eigen::VectorXd& v, std::int64_t k) {
    return v.template segment<C>(C * k);
  }
  static auto at(const Eigen::VectorXd& v, std::int64_t k) {
    return v.template segment<C>(C * k);
  }
  static double strain_of(const Term<C>& t, const Eigen::VectorXd& x) {
    return t.N.dot(t.vj * at(x, t.li) - t.vi * at(x, t.lj));
  }

  /// y = (M + R) x, adding each term to both its ends in term order.
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    const auto blocks = static_cast<std::int64_t>(sys_.blocks());
    for (std::int64_t k = 0; k < blocks; ++k) at(y, k) = reg_[k] * at(x, k);
    for (const auto& t : sys_.terms) {
      const double s = strain_of(t, x);
      at(y, t.li) += (t.kvj * s) * t.N;
      at(y, t.lj) -= (t.kvi * s) * t.N;
    }
  }

  void precondition(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
    const auto blocks = static_cast<std::int64_t>(sys_.blocks());
    for (std::int64_t k = 0; k < blocks; ++k) at(out, k) = inv_[k] * at(in, k);
  }

  const System<C>& sys_;
  std::vector<Mat<C>> reg_, inv_;
};

}  // namespace dhpd::interface_detail
