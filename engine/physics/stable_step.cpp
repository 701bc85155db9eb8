// Power iteration for the largest eigenvalue of the linearised bond stiffness (docs/theory.md §9).
#include "engine/physics/stable_step.hpp"

#include <bit>
#include <cmath>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd {
namespace {

/// out = M⁻¹ K u per unit mass density: (1/ρ_i) Σ_k K_k/|ξ_k| (e_k · (u_o − u_i)) e_k, negated.
template <int Dim>
void apply_stiffness(const BondRows& il, const ParticleStore& p, const std::vector<double>& u,
                     std::vector<double>& out) {
  const auto n = static_cast<std::int64_t>(p.size());
  const auto& X = p.reference_position;
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    double acc[Dim] = {};
    for (auto k = il.begin(i); k < il.end(i); ++k) {
      const auto o = static_cast<std::size_t>(il.other[k]);
      double e[Dim], ew = 0.0;
      for (int a = 0; a < Dim; ++a) {
        e[a] = (X[a][o] - X[a][i]) * il.inverse_length(k);
        ew += e[a] * (u[o * Dim + a] - u[i * Dim + a]);
      }
      const double scale = static_cast<double>(il.stiffness[k]) * il.stiffness_scale * p.volume[o] *
                           il.inverse_length(k) * ew;
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
  const auto n = static_cast<std::int64_t>(p.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    double s = 0.0;
    for (int d = 0; d < Dim; ++d) s += a[i * Dim + d] * b[i * Dim + d];
    part[i] = p.density[i] * p.volume[i] * s;
  }
  return ordered_sum(part);
}

/// ±1 per particle and axis from a fixed hash of (reference position, axis): rich in every
/// wavelength down to the spacing, and the same vector whatever the order of the slots.
template <int Dim>
void start_vector(const ParticleStore& p, std::vector<double>& u) {
  const std::size_t n = p.size();
  u.resize(n * Dim);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t where = 0x2545F4914F6CDD1Dull;
    for (int a = 0; a < Dim; ++a)
      where = (where ^ std::bit_cast<std::uint64_t>(p.reference_position[a][i])) *
              0x9E3779B97F4A7C15ull;
    for (int a = 0; a < Dim; ++a) {
      auto h = where + static_cast<std::uint64_t>(a + 1) * 0xBF58476D1CE4E5B9ull;
      h ^= h >> 31;
      h *= 0x94D049BB133111EBull;
      h ^= h >> 29;
      u[i * Dim + a] = (h >> 63) ? 1.0 : -1.0;
    }
  }
}

template <int Dim>
PowerEstimate iterate(const BondRows& il, const ParticleStore& p, int max_iterations,
                      double tolerance) {
  const std::size_t n = p.size();
  std::vector<double> u, ku(n * Dim);
  start_vector<Dim>(p, u);
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

/// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal a and off-diagonal b
/// (b[j] couples j and j+1), by bisection on Sturm counts (the number of eigenvalues below x is
/// the number of negative pivots of T − x I).
double largest_tridiagonal_eigenvalue(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t k = a.size();
  double lo = a[0], hi = a[0];
  for (std::size_t j = 0; j < k; ++j) {
    const double r = (j > 0 ? std::abs(b[j - 1]) : 0.0) + (j + 1 < k ? std::abs(b[j]) : 0.0);
    lo = std::max(lo, a[j]);  // the largest eigenvalue is at least the largest diagonal entry
    hi = std::max(hi, a[j] + r);
  }
  auto below = [&](double x) {  // eigenvalues < x
    std::size_t count = 0;
    double d = 1.0;
    for (std::size_t j = 0; j < k; ++j) {
      const double off = j > 0 ? b[j - 1] * b[j - 1] : 0.0;
      d = a[j] - x - (j > 0 ? off / d : 0.0);
      if (d == 0.0) d = -1e-300;  // x on a pivot: count it as below
      count += d < 0.0;
    }
    return count;
  };
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (below(mid) == k ? hi : lo) = mid;
  }
  return hi;
}

/// Lanczos in the mass inner product (M⁻¹K is symmetric in it), without reorthogonalisation:
/// the largest Ritz value converges first and lost orthogonality only adds copies of it.
/// Weighs the start vector towards the stiffest particles, where the top modes live: particle i's
/// components times (Δt_min / Δt_i)³ of the per-particle bounds (1 for the stiffest, 1/8 for a
/// particle whose bound is twice theirs, as a coarse particle next to a refined zone).
template <int Dim>
void weigh_towards_stiffest(const std::vector<double>& particle_dt, std::vector<double>& v) {
  double least = HUGE_VAL;
  for (const double dt : particle_dt) least = std::min(least, dt);
  if (!std::isfinite(least)) return;
  for (std::size_t i = 0; i < particle_dt.size(); ++i) {
    const double r = std::isfinite(particle_dt[i]) ? least / particle_dt[i] : 0.0;
    for (int a = 0; a < Dim; ++a) v[i * Dim + a] *= r * r * r;
  }
}

template <int Dim, class Apply>
PowerEstimate lanczos(const Apply& apply, const ParticleStore& p, int max_iterations,
                      double tolerance, const std::vector<double>* particle_dt) {
  const std::size_t n = p.size();
  std::vector<double> v, previous(n * Dim, 0.0), w(n * Dim);
  start_vector<Dim>(p, v);
  if (particle_dt && particle_dt->size() == n) weigh_towards_stiffest<Dim>(*particle_dt, v);
  const double start_norm = std::sqrt(mass_dot<Dim>(p, v, v));
  for (auto& x : v) x /= start_norm;
  std::vector<double> alpha, beta;
  PowerEstimate e;
  for (e.iterations = 1; e.iterations <= max_iterations; ++e.iterations) {
    apply(v, w);
    const double a = mass_dot<Dim>(p, w, v);
    const double b_prev = beta.empty() ? 0.0 : beta.back();
    const auto size = static_cast<std::int64_t>(w.size());
#pragma omp parallel for schedule(static) if (size >= kParallelMinParticles)
    for (std::int64_t k = 0; k < size; ++k) w[k] -= a * v[k] + b_prev * previous[k];
    alpha.push_back(a);
    const double theta = largest_tridiagonal_eigenvalue(alpha, beta);
    e.last_change = e.omega2 > 0.0 ? std::abs(theta - e.omega2) / theta : 1.0;
    e.omega2 = theta;
    const double b = std::sqrt(mass_dot<Dim>(p, w, w));
    // Converged: ω² still within the tolerance after a few more vectors (Ritz values of the top
    // only grow, and stall briefly before a jump is rare after the first few iterations).
    if (e.iterations >= 8 && e.last_change < tolerance) break;
    if (!(b > 1e-12 * std::abs(a))) break;  // an invariant subspace: T holds its eigenvalues
    beta.push_back(b);
    previous.swap(v);
#pragma omp parallel for schedule(static) if (size >= kParallelMinParticles)
    for (std::int64_t k = 0; k < size; ++k) v[k] = w[k] / b;
  }
  e.iterations = std::min(e.iterations, max_iterations);
  e.dt = e.omega2 > 0.0 ? 2.0 / std::sqrt(e.omega2) : HUGE_VAL;
  return e;
}

}  // namespace

PowerEstimate lanczos_stable_step(const BondRows& il, const ParticleStore& p, int max_iterations,
                                  double tolerance, const std::vector<double>* particle_dt) {
  return with_dim(p.dim(), [&](auto d) {
    constexpr int Dim = d();
    const auto apply = [&](const std::vector<double>& u, std::vector<double>& out) {
      apply_stiffness<Dim>(il, p, u, out);
    };
    return lanczos<Dim>(apply, p, max_iterations, tolerance, particle_dt);
  });
}

PowerEstimate lanczos_stable_step(const StiffnessOperator& apply, const ParticleStore& p,
                                  int max_iterations, double tolerance,
                                  const std::vector<double>* particle_dt) {
  return with_dim(p.dim(), [&](auto d) {
    return lanczos<d()>(apply, p, max_iterations, tolerance, particle_dt);
  });
}

PowerEstimate largest_stable_step(const BondRows& il, const ParticleStore& p, int max_iterations,
                                  double tolerance) {
  return with_dim(p.dim(), [&](auto d) { return iterate<d()>(il, p, max_iterations, tolerance); });
}

}  // namespace dhpd
