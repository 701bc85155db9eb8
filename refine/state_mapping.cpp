// Children's displacement and velocity at a refinement event: copy (IJNME 2016 §5.3) or
// least-squares fits over the parent's intact bonds (docs/scenes.md `mapping`; docs/theory.md
// §13.4).
#include "refine/state_mapping.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "refine/split_plan.hpp"

namespace dhpd::refine {

using geometry::Vec3;

namespace {

constexpr int kMaxBasis = 9;  // 3 gradient + 6 Hessian terms in 3D
using Normal = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxBasis, kMaxBasis>;
using Basis = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBasis, 1>;
using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxBasis, 6>;

/// Hessian entries used in each dimension, as (a, b, slot in FieldFit::H).
struct HessianTerm {
  int a, b, slot;
};
constexpr HessianTerm kTerms2[] = {{0, 0, 0}, {1, 1, 1}, {0, 1, 3}};
constexpr HessianTerm kTerms3[] = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2},
                                   {0, 1, 3}, {0, 2, 4}, {1, 2, 5}};

int hessian_terms(int dim) {
  return dim == 1 ? 1 : (dim == 2 ? 3 : 6);
}
const HessianTerm* terms_of(int dim) {
  static constexpr HessianTerm one[] = {{0, 0, 0}};
  return dim == 1 ? one : (dim == 2 ? kTerms2 : kTerms3);
}

/// Basis of the fit at offset e (in units of the parent's spacing): e, then ½ e_a² and e_a e_b.
Basis basis(const double e[3], int dim, bool quadratic) {
  Basis phi(dim + (quadratic ? hessian_terms(dim) : 0));
  for (int a = 0; a < dim; ++a) phi(a) = e[a];
  if (quadratic)
    for (int t = 0; t < hessian_terms(dim); ++t) {
      const auto& h = terms_of(dim)[t];
      phi(dim + t) = h.a == h.b ? 0.5 * e[h.a] * e[h.a] : e[h.a] * e[h.b];
    }
  return phi;
}

/// Solves M c = R by the pseudo-inverse (eigenvalues below 1e-10 of the largest dropped).
/// Returns the rank.
int solve_pseudo(const Normal& M, const Rhs& R, Rhs& c) {
  const Eigen::SelfAdjointEigenSolver<Normal> es(M);
  const auto& lambda = es.eigenvalues();
  const double largest = lambda.cwiseAbs().maxCoeff();
  Normal inverse = Normal::Zero(M.rows(), M.cols());
  int rank = 0;
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    if (!(lambda(k) > 1e-10 * largest)) continue;
    const auto v = es.eigenvectors().col(k);
    inverse += (v / lambda(k)) * v.transpose();
    ++rank;
  }
  c = inverse * R;
  return rank;
}

/// One least-squares solve over i's intact own bonds; false when the basis is not resolved.
bool fit_once(const ParticleStore& p, const BondRows& b, PartialVolume rule, std::size_t i,
              bool quadratic, const std::vector<std::int32_t>& held, ParentFit& out) {
  auto is_held = [&](std::size_t x) {
    return std::binary_search(held.begin(), held.end(), static_cast<std::int32_t>(x));
  };
  const bool i_held = !held.empty() && is_held(i);
  const int d = p.dim();
  const double h = p.spacing[i];  // offsets in units of h keep the normal matrix well scaled
  const int n = d + (quadratic ? hessian_terms(d) : 0);
  Normal M = Normal::Zero(n, n);
  Rhs R = Rhs::Zero(n, 6);
  for (auto k = b.begin(i); k < b.end(i); ++k) {
    if (!b.own_intact(k)) continue;
    const auto j = static_cast<std::size_t>(b.other[k]);
    if (!held.empty() && is_held(j) != i_held) continue;
    double e[3] = {0, 0, 0};
    for (int a = 0; a < d; ++a)
      e[a] = (p.reference_position[a][j] - p.reference_position[a][i]) / h;
    const double w = bond_weight(p, rule, i, j, b.length(k)) * p.volume[j];
    const Basis phi = basis(e, d, quadratic);
    M.noalias() += w * phi * phi.transpose();
    for (int r = 0; r < d; ++r) {
      R.col(r) += (w * (p.displacement[r][j] - p.displacement[r][i])) * phi;
      R.col(3 + r) += (w * (p.velocity[r][j] - p.velocity[r][i])) * phi;
    }
  }
  if (M.isZero(0.0)) return false;
  Rhs c;
  const int rank = solve_pseudo(M, R, c);
  if (quadratic && rank < n) return false;
  const FitRank fit_rank = rank == n ? FitRank::Full : FitRank::Reduced;
  for (auto* f : {&out.displacement, &out.velocity}) {
    const int col = f == &out.displacement ? 0 : 3;
    *f = FieldFit{};
    f->rank = fit_rank;
    for (int r = 0; r < d; ++r) {
      for (int a = 0; a < d; ++a) f->G[r][a] = c(a, col + r) / h;
      if (quadratic)
        for (int t = 0; t < hessian_terms(d); ++t)
          f->H[r][terms_of(d)[t].slot] = c(d + t, col + r) / (h * h);
    }
  }
  return true;
}

}  // namespace

double FieldFit::change(int r, const Vec3& o, int dim) const {
  double w = 0.0;
  for (int a = 0; a < dim; ++a) w += G[r][a] * o[a];
  for (int t = 0; t < hessian_terms(dim); ++t) {
    const auto& term = terms_of(dim)[t];
    const double hv = H[r][term.slot];
    w += term.a == term.b ? 0.5 * hv * o[term.a] * o[term.a] : hv * o[term.a] * o[term.b];
  }
  return w;
}

ParentFit fit_parent(const ParticleStore& p, const BondRows& bonds, PartialVolume rule,
                     std::size_t i, bool quadratic, const std::vector<std::int32_t>& held) {
  ParentFit fit;
  if (quadratic && fit_once(p, bonds, rule, i, true, held, fit)) return fit;
  if (!fit_once(p, bonds, rule, i, false, held, fit)) fit = ParentFit{};
  return fit;
}

ChildState map_state(const SplitPlan& plan, StateMapping mapping, const ParticleStore& p,
                     const BondRows& bonds, PartialVolume rule,
                     const std::vector<std::int32_t>& held,
                     const std::vector<std::int32_t>& donor) {
  ChildState s;
  const int d = p.dim();
  const std::size_t n = plan.child_slot.size();
  s.displacement.resize(n);
  s.velocity.resize(n);
  const bool quadratic = mapping == StateMapping::Quadratic;
  auto fit_of = [&](std::size_t i) {
    return mapping == StateMapping::Copy ? ParentFit{}
                                         : fit_parent(p, bonds, rule, i, quadratic, held);
  };
  std::vector<Vec3> du, dv;  // per child of one parent: the change from the parent's u and v
  for (std::size_t c = 0; c < n;) {  // the children of one parent are consecutive
    const auto k = plan.child_parent[c];
    const auto q = static_cast<std::size_t>(plan.parents[static_cast<std::size_t>(k)]);
    const std::size_t end = c + static_cast<std::size_t>(plan.child_count[k]);
    const ParentFit fit = fit_of(q);
    s.reduced_fits += fit.displacement.rank == FitRank::Reduced ? 1 : 0;
    du.assign(end - c, Vec3{0, 0, 0});
    dv.assign(end - c, Vec3{0, 0, 0});
    for (std::size_t m = c; m < end; ++m) {
      // A child across a pre-crack from its parent takes the field of its own side: the donor's
      // fit evaluated at the child.
      const bool across = !donor.empty() && donor[m] >= 0;
      const auto from = across ? static_cast<std::size_t>(donor[m]) : q;
      const ParentFit own = across ? fit_of(from) : ParentFit{};
      const ParentFit& f = across ? own : fit;
      const Vec3 o = plan.child_position[m] - point_of(p.reference_position, from);
      for (int r = 0; r < d; ++r) {
        du[m - c][r] =
            p.displacement[r][from] - p.displacement[r][q] + f.displacement.change(r, o, d);
        dv[m - c][r] = p.velocity[r][from] - p.velocity[r][q] + f.velocity.change(r, o, d);
      }
    }
    // u is the field at the child; v less the siblings' mean change, so Σ m_c v_c = m_q v_q.
    double mean_dv[3] = {0, 0, 0};
    for (const auto& x : dv)
      for (int r = 0; r < d; ++r) mean_dv[r] += x[r] / static_cast<double>(end - c);
    for (std::size_t m = c; m < end; ++m)
      for (int r = 0; r < 3; ++r) {
        s.displacement[m][r] = p.displacement[r][q] + (r < d ? du[m - c][r] : 0.0);
        s.velocity[m][r] = p.velocity[r][q] + (r < d ? dv[m - c][r] - mean_dv[r] : 0.0);
      }
    c = end;
  }
  return s;
}

}  // namespace dhpd::refine
