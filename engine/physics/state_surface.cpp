// Surface correction of the ordinary state-based family (docs/theory.md §20.5; the factors of
// Madenci & Oterkus, Peridynamic Theory and Its Applications (2014) §4.2, for this model's terms).
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <optional>

#include "engine/base/parallel.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd {
namespace {

/// A symmetric tensor as its strain_count(n) components (off-diagonals counted twice): n·B·n =
/// Σ_k b_k n_a n_b.
using SymmetricTensor = std::array<double, 6>;

/// B_i of the exact dilatation (docs/theory.md §20.5): Σ_j w |ξ|² (n·B·n) n⊗n = I over i's own
/// bonds, so that θ_i = Σ_j w |ξ| (n·B·n) e is the trace of every uniform strain; none when the
/// fourth moments are singular or B is not positive along every own bond (a horizon too thin in
/// some direction), where the axes' ellipse stays.
std::optional<SymmetricTensor> exact_dilatation_tensor(const BondRows& rows, const ParticleStore& p,
                                                       std::size_t i, int n,
                                                       const std::vector<double>& own_weight) {
  const int c = strain_count(n);
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  Matrix A = Matrix::Zero(c, c);
  Vector rhs = Vector::Zero(c);
  const auto products = [&](std::int64_t k, double out[6]) {
    const auto j = static_cast<std::size_t>(rows.other[k]);
    const double length = rows.length(k);
    double na[3] = {0, 0, 0};
    for (int a = 0; a < n; ++a)
      na[a] = (p.reference_position[a][j] - p.reference_position[a][i]) / length;
    for (int q = 0; q < c; ++q) {
      int a = 0, b = 0;
      strain_axes(n, q, a, b);
      out[q] = na[a] * na[b];
    }
  };
  for (auto k = rows.begin(i); k < rows.end(i); ++k) {
    if (!rows.has_own(k)) continue;
    double nn[6];
    products(k, nn);
    const double length = rows.length(k), w = own_weight[k] * length * length;
    for (int q = 0; q < c; ++q)
      for (int r = 0; r < c; ++r) A(q, r) += w * nn[q] * nn[r];
  }
  for (int q = 0; q < n; ++q) rhs(q) = 1.0;  // the diagonal components of I
  const Eigen::LDLT<Matrix> ldlt(A);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const double scale = A.diagonal().maxCoeff();
  if (!(ldlt.vectorD().minCoeff() > 1e-8 * scale)) return std::nullopt;
  const Vector b = ldlt.solve(rhs);
  SymmetricTensor out{};
  for (int q = 0; q < c; ++q) out[static_cast<std::size_t>(q)] = b(q);
  for (auto k = rows.begin(i); k < rows.end(i); ++k) {  // positive along every own bond
    if (!rows.has_own(k)) continue;
    double nn[6], along = 0.0;
    products(k, nn);
    for (int q = 0; q < c; ++q) along += out[static_cast<std::size_t>(q)] * nn[q];
    if (!(along > 0.0)) return std::nullopt;
  }
  return out;
}

using Axes = std::array<double, 3>;

/// Each particle's factors: per axis, the dilatation's (d) and the deviatoric term's (b), and the
/// exact dilatation's tensor scaled by m_i/n (1 inside a lattice) where it exists.
struct ParticleFactors {
  std::vector<Axes> dilatation, deviatoric;
  std::vector<std::optional<SymmetricTensor>> exact;
};

/// Per particle and axis a, a uniaxial strain ε along a: the continuum's θ = ε and deviatoric
/// energy G ε² (1 − 1/n) over the particle's own (θ = ε (n/m) Σ w |ξ|² n_a²; e^d = ε |ξ| (n_a² −
/// 1/n) with θ at its continuum value); and the exact tensor.
ParticleFactors particle_factors(const BondRows& rows, const ParticleStore& p,
                                 const OrdinaryStateInputs& in, const std::vector<double>& m,
                                 const std::vector<double>& own_weight) {
  const int n = in.section.dim;
  const std::size_t count = p.size();
  ParticleFactors f{std::vector<Axes>(count, Axes{1, 1, 1}),
                    std::vector<Axes>(count, Axes{1, 1, 1}),
                    std::vector<std::optional<SymmetricTensor>>(count)};
  const auto N = static_cast<std::int64_t>(count);
#pragma omp parallel for schedule(static) if (N >= kParallelMinParticles)
  for (std::int64_t s = 0; s < N; ++s) {
    const auto i = static_cast<std::size_t>(s);
    if (!(m[i] > 0.0)) continue;
    const auto moduli =
        state_moduli((*in.materials)[static_cast<std::size_t>(p.material[i])], in.section);
    const double Q = n * (n + 2.0) * moduli.shear / m[i];
    for (int a = 0; a < n; ++a) {
      double second = 0.0, deviatoric = 0.0;
      for (auto k = rows.begin(i); k < rows.end(i); ++k) {
        if (!rows.has_own(k)) continue;
        const double length = rows.length(k);
        const auto j = static_cast<std::size_t>(rows.other[k]);
        const double na = (p.reference_position[a][j] - p.reference_position[a][i]) / length;
        const double w = own_weight[k] * length * length;
        second += w * na * na;
        deviatoric += w * (na * na - 1.0 / n) * (na * na - 1.0 / n);
      }
      const double theta = n * second / m[i];
      if (theta > 0.0) f.dilatation[i][a] = 1.0 / theta;
      if (n > 1 && deviatoric > 0.0)
        f.deviatoric[i][a] = moduli.shear * (1.0 - 1.0 / n) / (0.5 * Q * deviatoric);
    }
    if (n > 1 && (f.exact[i] = exact_dilatation_tensor(rows, p, i, n, own_weight)))
      for (auto& b : *f.exact[i]) b *= m[i] / n;
  }
  return f;
}

}  // namespace

SurfaceFactors surface_factors(const BondRows& rows, const ParticleStore& p,
                               const OrdinaryStateInputs& in, const std::vector<double>& m,
                               const std::vector<double>& own_weight) {
  const int n = in.section.dim;
  const auto f = particle_factors(rows, p, in, m, own_weight);
  // Per entry: the owner's factors read along the bond, the deviatoric ones (and the dilatation
  // ones without an exact tensor) as an ellipse (ellipsoid): i's for its own bond, j's for the
  // bond j owns on i (the reaction of j's state, which row j computes the same).
  SurfaceFactors out;
  for (auto* v :
       {&out.own_dilatation, &out.own_deviatoric, &out.dual_dilatation, &out.dual_deviatoric})
    v->assign(rows.flags.size(), 1.0);
  const auto along = [&](const Axes& axes, const double* na) {
    double sum = 0.0;
    for (int a = 0; a < n; ++a) sum += (na[a] / axes[a]) * (na[a] / axes[a]);
    return 1.0 / std::sqrt(sum);
  };
  const auto dilatation = [&](std::size_t i, const double* na) {
    if (!f.exact[i]) return along(f.dilatation[i], na);
    double sum = 0.0;
    for (int q = 0; q < strain_count(n); ++q) {
      int a = 0, b = 0;
      strain_axes(n, q, a, b);
      sum += (*f.exact[i])[static_cast<std::size_t>(q)] * na[a] * na[b];
    }
    return sum;
  };
  const auto N = static_cast<std::int64_t>(p.size());
#pragma omp parallel for schedule(static) if (N >= kParallelMinParticles)
  for (std::int64_t s = 0; s < N; ++s) {
    const auto i = static_cast<std::size_t>(s);
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = rows.length(k);
      double na[3] = {0, 0, 0};
      for (int a = 0; a < n; ++a)
        na[a] = (p.reference_position[a][j] - p.reference_position[a][i]) / length;
      out.own_dilatation[k] = dilatation(i, na);
      out.own_deviatoric[k] = along(f.deviatoric[i], na);
      out.dual_dilatation[k] = dilatation(j, na);
      out.dual_deviatoric[k] = along(f.deviatoric[j], na);
    }
  }
  return out;
}

}  // namespace dhpd
