// Correspondence (non-ordinary state-based) DH-PD, small-strain linear elasticity (docs/theory.md
// §21; IJNME 2016 eqs. 45–56; Silling, J. Elasticity 127 (2017) 269 for the stabilisation).
#include "engine/physics/correspondence.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd {
namespace {

/// λ and μ of Hooke's law in the dimension: plane stress λ* = Eν/(1−ν²); 1D σ = E ε.
std::array<double, 2> hooke(const Material& m, const Section& s) {
  if (s.dim == 1) return {m.E, 0.0};
  const double nu = poisson_ratio(m, s), mu = m.E / (2.0 * (1.0 + nu));
  if (s.dim == 2 && s.plane == PlaneMode::Stress) return {m.E * nu / (1.0 - nu * nu), mu};
  return {m.E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu};
}

}  // namespace

Correspondence::Correspondence(const BondRows& rows, const ParticleStore& p,
                               const OrdinaryStateInputs& in, double stabilisation) {
  const std::size_t count = p.size();
  shape_inverse_.assign(count, Tensor{});
  gradient_.assign(count, Tensor{});
  stress_kinv_.assign(count, Tensor{});
  span_.assign(count, Tensor{});
  lambda_.assign(count, 0.0);
  mu_.assign(count, 0.0);
  stab_.assign(count, 0.0);
  own_weight_.assign(rows.flags.size(), 0.0);
  dual_weight_.assign(rows.flags.size(), 0.0);
  const int dim = in.section.dim;
  const auto omega = [&](std::size_t owner, double length) {
    return in.influence == Influence::Constant ? 1.0 : p.horizon[owner] / length;
  };
  for_each_particle(count, [&](std::size_t i) {
    Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = rows.length(k);
      if (rows.has_own(k)) {
        own_weight_[k] = omega(i, length) * bond_weight(p, in.rule, i, j, length) * p.volume[j];
        Eigen::Vector3d xi = Eigen::Vector3d::Zero();
        for (int a = 0; a < dim; ++a)
          xi[a] = p.reference_position[a][j] - p.reference_position[a][i];
        K += own_weight_[k] * xi * xi.transpose();
      }
      if (rows.has_dual(k))
        dual_weight_[k] = omega(j, length) * bond_weight(p, in.rule, j, i, length) * p.volume[j];
    }
    // K⁻¹ over the dimension's block; where the bonds do not span it (a particle with a few
    // collinear bonds) the pseudo-inverse, so that H K = A on the bonds' span and the moments
    // still balance (eigenvalues below 1e-10 of the largest dropped).
    Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
    const Eigen::MatrixXd block = K.topLeftCorner(dim, dim);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(block);
    const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::VectorXd inv_values = Eigen::VectorXd::Zero(dim);
    for (int r = 0; r < dim; ++r)
      if (eig.eigenvalues()[r] > 1e-10 * largest) inv_values[r] = 1.0 / eig.eigenvalues()[r];
    inverse.topLeftCorner(dim, dim) =
        eig.eigenvectors() * inv_values.asDiagonal() * eig.eigenvectors().transpose();
    Eigen::Matrix3d projector = Eigen::Matrix3d::Zero();  // onto the bonds' span: K⁺ K
    projector.topLeftCorner(dim, dim) = inverse.topLeftCorner(dim, dim) * block;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) span_[i][3 * r + c] = projector(r, c);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) shape_inverse_[i][3 * r + c] = inverse(r, c);
    const auto& mat = (*in.materials)[static_cast<std::size_t>(p.material[i])];
    const auto lm = hooke(mat, in.section);
    lambda_[i] = lm[0];
    mu_[i] = lm[1];
    stab_[i] = stabilisation * micromodulus(mat, in.section, p.horizon[i]) / p.horizon[i];
  });
}

template <int Dim>
void Correspondence::state_pass(const BondRows& rows, const ParticleStore& p,
                                const double* const u[3], const std::vector<std::int32_t>* subset) {
  for_each_particle(p.size(), subset, [&](std::size_t i) {
    // H = (Σ w Δu ⊗ ξ) K⁻¹, ε = sym H, σ = λ tr ε I + 2μ ε.
    double A[Dim][Dim] = {};
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      if (!rows.own_intact(k)) continue;
      const auto j = static_cast<std::size_t>(rows.other[k]);
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b)
          A[a][b] += own_weight_[k] * (u[a][j] - u[a][i]) *
                     (p.reference_position[b][j] - p.reference_position[b][i]);
    }
    const auto &Ki = shape_inverse_[i], &P = span_[i];
    double H[Dim][Dim] = {}, sym[Dim][Dim], eps[Dim][Dim] = {}, sigma[Dim][Dim], trace = 0.0;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        for (int c = 0; c < Dim; ++c) H[a][b] += A[a][c] * Ki[3 * c + b];
    // ε = P sym(H) P (P = I where the bonds span the space): a rotation strains nothing.
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b) sym[a][b] = 0.5 * (H[a][b] + H[b][a]);
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        for (int c = 0; c < Dim; ++c)
          for (int d = 0; d < Dim; ++d) eps[a][b] += P[3 * a + c] * sym[c][d] * P[3 * d + b];
    for (int a = 0; a < Dim; ++a) trace += eps[a][a];
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        sigma[a][b] = (a == b ? lambda_[i] * trace : 0.0) + 2.0 * mu_[i] * eps[a][b];
    // The force's stress: ∂W/∂H = P σ P, times K⁺ (P K⁺ = K⁺).
    Tensor sk{};
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b) {
        gradient_[i][3 * a + b] = H[a][b];
        for (int c = 0; c < Dim; ++c)
          for (int d = 0; d < Dim; ++d) sk[3 * a + b] += P[3 * a + c] * sigma[c][d] * Ki[3 * d + b];
      }
    stress_kinv_[i] = sk;
  });
}

template <int Dim>
void Correspondence::force_pass(const BondRows& rows, const ParticleStore& p,
                                const double* const u[3], double* const out[3], bool per_density,
                                const std::vector<std::int32_t>* subset) {
  for_each_particle(p.size(), subset, [&](std::size_t i) {
    double f[Dim] = {};
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const bool own = rows.own_intact(k), dual = rows.dual_intact(k);
      if (!own && !dual) continue;
      const auto j = static_cast<std::size_t>(rows.other[k]);
      double xi[Dim], du[Dim];
      for (int a = 0; a < Dim; ++a) {
        xi[a] = p.reference_position[a][j] - p.reference_position[a][i];
        du[a] = u[a][j] - u[a][i];
      }
      // t = w [σ K⁻¹ ξ + G_s (Δu − H ξ)] with the owner's σ K⁻¹, H, G_s (i's own bond, j's dual).
      const auto add = [&](std::size_t o, double w) {
        for (int a = 0; a < Dim; ++a) {
          double t = 0.0, hx = 0.0;
          for (int b = 0; b < Dim; ++b) {
            t += stress_kinv_[o][3 * a + b] * xi[b];
            hx += gradient_[o][3 * a + b] * xi[b];
          }
          f[a] += w * (t + stab_[o] * (du[a] - hx));
        }
      };
      if (own) add(i, own_weight_[k]);
      if (dual) add(j, dual_weight_[k]);
    }
    for (int a = 0; a < Dim; ++a) out[a][i] = per_density ? -f[a] / p.density[i] : f[a];
  });
}

void Correspondence::forces(const BondRows& rows, ParticleStore& p,
                            const std::vector<std::int32_t>* subset,
                            const std::function<void()>& between) {
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const double* const u[3] = {p.displacement[0].data(), p.displacement[1].data(),
                                p.displacement[2].data()};
    state_pass<Dim>(rows, p, u, subset);
    if (between) between();
    double* const out[3] = {p.force_density[0].data(), p.force_density[1].data(),
                            p.force_density[2].data()};
    force_pass<Dim>(rows, p, u, out, false, subset);
    return 0;
  });
}

void Correspondence::stiffness_times(const BondRows& rows, const ParticleStore& p,
                                     const std::vector<double>& u, std::vector<double>& out) {
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    std::vector<double> axes_in[3], axes_out[3];
    for (int a = 0; a < Dim; ++a) {
      axes_in[a].resize(p.size());
      axes_out[a].resize(p.size());
      for (std::size_t i = 0; i < p.size(); ++i) axes_in[a][i] = u[i * Dim + a];
    }
    const double* const in[3] = {axes_in[0].data(), axes_in[1].data(), axes_in[2].data()};
    double* const target[3] = {axes_out[0].data(), axes_out[1].data(), axes_out[2].data()};
    state_pass<Dim>(rows, p, in);
    force_pass<Dim>(rows, p, in, target, true);
    out.resize(p.size() * Dim);
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int a = 0; a < Dim; ++a) out[i * Dim + a] = axes_out[a][i];
    return 0;
  });
}

double Correspondence::strain_energy(const BondRows& rows, const ParticleStore& p) {
  std::vector<double> energy(p.size(), 0.0);
  with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const double* const u[3] = {p.displacement[0].data(), p.displacement[1].data(),
                                p.displacement[2].data()};
    state_pass<Dim>(rows, p, u);
    for_each_particle(p.size(), [&](std::size_t i) {
      // ½ σ : ε = ½ (σ K⁻¹) K : sym H; with σ symmetric, ½ σ : H. σ = (σ K⁻¹) K is not kept:
      // recompute σ from H.
      const auto &H = gradient_[i], &P = span_[i];
      double eps[Dim][Dim] = {}, trace = 0.0, work = 0.0;
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b)
          for (int c = 0; c < Dim; ++c)
            for (int d = 0; d < Dim; ++d)
              eps[a][b] += P[3 * a + c] * 0.5 * (H[3 * c + d] + H[3 * d + c]) * P[3 * d + b];
      for (int a = 0; a < Dim; ++a) trace += eps[a][a];
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b)
          work += ((a == b ? lambda_[i] * trace : 0.0) + 2.0 * mu_[i] * eps[a][b]) * eps[a][b];
      double stab = 0.0;
      for (auto k = rows.begin(i); k < rows.end(i); ++k) {
        if (!rows.own_intact(k)) continue;
        const auto j = static_cast<std::size_t>(rows.other[k]);
        for (int a = 0; a < Dim; ++a) {
          double hx = 0.0;
          for (int b = 0; b < Dim; ++b)
            hx += H[3 * a + b] * (p.reference_position[b][j] - p.reference_position[b][i]);
          const double z = u[a][j] - u[a][i] - hx;
          stab += own_weight_[k] * z * z;
        }
      }
      energy[i] = p.volume[i] * 0.5 * (work + stab_[i] * stab);
    });
    return 0;
  });
  return ordered_sum(energy);
}

std::size_t Correspondence::bytes() const {
  std::size_t b =
      (shape_inverse_.capacity() + gradient_.capacity() + stress_kinv_.capacity()) * sizeof(Tensor);
  for (const auto* v : {&lambda_, &mu_, &stab_, &own_weight_, &dual_weight_})
    b += v->capacity() * sizeof(double);
  return b;
}

}  // namespace dhpd
