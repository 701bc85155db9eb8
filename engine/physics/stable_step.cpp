// Power iteration for the largest eigenvalue of the linearised bond stiffness (docs/theory.md §9).
#include "engine/physics/stable_step.hpp"

#include <cmath>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd {
namespace {

/// out = M⁻¹ K u per unit mass density: (1/ρ_i) Σ_k K_k/|ξ_k| (e_k · (u_o − u_i)) e_k, negated.
template <int Dim>
void apply_stiffness(const InteractionList& il, const ParticleStore& p,
                     const std::vector<double>& u, std::vector<double>& out) {
  const auto n = static_cast<std::int64_t>(p.size());
  const auto& X = p.reference_position;
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    double acc[Dim] = {};
    for (auto k = il.begin(i); k < il.end(i); ++k) {
      const auto o = static_cast<std::size_t>(il.other[k]);
      double e[Dim], ew = 0.0;
      for (int a = 0; a < Dim; ++a) {
        e[a] = (X[a][o] - X[a][i]) * il.inv_length[k];
        ew += e[a] * (u[o * Dim + a] - u[i * Dim + a]);
      }
      const double scale = il.coefficient[k] * il.inv_length[k] * ew;
      for (int a = 0; a < Dim; ++a) acc[a] += scale * e[a];
    }
    for (int a = 0; a < Dim; ++a) out[i * Dim + a] = -acc[a] / p.density[i];
  }
}

/// Σ m_i a_i·b_i with m_i = ρ_i V_i (the mass inner product in which M⁻¹K is symmetric).
template <int Dim>
double mass_dot(const ParticleStore& p, const std::vector<double>& a,
                const std::vector<double>& b) {
  std::vector<double> part(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    double s = 0.0;
    for (int d = 0; d < Dim; ++d) s += a[i * Dim + d] * b[i * Dim + d];
    part[i] = p.density[i] * p.volume[i] * s;
  }
  return ordered_sum(part);
}

template <int Dim>
PowerEstimate iterate(const InteractionList& il, const ParticleStore& p, int max_iterations,
                      double tolerance) {
  const std::size_t n = p.size();
  std::vector<double> u(n * Dim), ku(n * Dim);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < Dim; ++a) {
      // A fixed hash of (slot, axis): ±1, rich in every wavelength down to the spacing.
      auto h =
          static_cast<std::uint64_t>(i + 1) * 0x9E3779B97F4A7C15ull + a * 0xBF58476D1CE4E5B9ull;
      h ^= h >> 31;
      h *= 0x94D049BB133111EBull;
      u[i * Dim + a] = (h >> 63) ? 1.0 : -1.0;
    }
  PowerEstimate e;
  for (e.iterations = 1; e.iterations <= max_iterations; ++e.iterations) {
    apply_stiffness<Dim>(il, p, u, ku);
    const double uu = mass_dot<Dim>(p, u, u);
    const double omega2 = mass_dot<Dim>(p, u, ku) / uu;  // Rayleigh quotient, ≤ ω²_max
    e.last_change = std::abs(omega2 - e.omega2) / omega2;
    e.omega2 = omega2;
    const double norm = std::sqrt(mass_dot<Dim>(p, ku, ku));
    if (!(norm > 0.0)) break;
    for (std::size_t k = 0; k < u.size(); ++k) u[k] = ku[k] / norm;
    if (e.last_change < tolerance) break;
  }
  e.iterations = std::min(e.iterations, max_iterations);
  e.dt = e.omega2 > 0.0 ? 2.0 / std::sqrt(e.omega2) : HUGE_VAL;
  return e;
}

}  // namespace

PowerEstimate largest_stable_step(const InteractionList& il, const ParticleStore& p,
                                  int max_iterations, double tolerance) {
  return with_dim(p.dim(), [&](auto d) { return iterate<d()>(il, p, max_iterations, tolerance); });
}

}  // namespace dhpd
