// Adaptive dynamic relaxation (docs/theory.md §22; horizon-size paper eqs. 27–28; Kilic & Madenci
// 2010 for the damping): per-particle sweeps with sums in fixed blocks.
#include "engine/physics/relaxation.hpp"

#include <algorithm>
#include <cmath>

#include "engine/base/parallel.hpp"

namespace dhpd {
namespace {

struct Pair {
  double a = 0.0, b = 0.0;
  Pair& operator+=(const Pair& o) {
    a += o.a, b += o.b;
    return *this;
  }
};

bool is_free(const RelaxationState& s, std::size_t i, int a) {
  return !(s.held[i] >> a & 1u);
}

}  // namespace

ResidualNorms residual_norms(const ParticleStore& p, const RelaxationState& s) {
  const int dim = p.dim();
  const auto sums = blocked_sum<Pair>(p.size(), [&](std::size_t i, Pair& out) {
    for (int a = 0; a < dim; ++a) {
      const double f = p.volume[i] * p.force_density[a][i];
      (is_free(s, i, a) ? out.a : out.b) += f * f;
    }
  });
  return {sums.a, sums.b};
}

double relaxation_damping(const ParticleStore& p, const RelaxationState& s) {
  const int dim = p.dim();
  // Σ u K₁ u and Σ u u over free components.
  const auto q = blocked_sum<Pair>(p.size(), [&](std::size_t i, Pair& out) {
    for (int a = 0; a < dim; ++a) {
      if (!is_free(s, i, a)) continue;
      const double u = p.displacement[a][i], w = p.velocity[a][i];
      const double step = s.tau2[i] * p.force_density[a][i] / p.density[i];
      const std::size_t k = static_cast<std::size_t>(dim) * i + static_cast<std::size_t>(a);
      if (w != 0.0) out.a += u * u * (-(step - s.last_step[k]) / w);
      out.b += u * u;
    }
  });
  if (!(q.a > 0.0) || !(q.b > 0.0)) return 0.0;
  return std::min(2.0 * std::sqrt(q.a / q.b), 1.9);
}

namespace {
/// w = (keep w + gain τ²F/ρ) on free components, u += w, positions follow; last_step updated.
void advance(ParticleStore& p, RelaxationState& s, double keep, double gain) {
  const int dim = p.dim();
  for_each_particle(p.size(), [&](std::size_t i) {
    for (int a = 0; a < dim; ++a) {
      const std::size_t k = static_cast<std::size_t>(dim) * i + static_cast<std::size_t>(a);
      const double step = s.tau2[i] * p.force_density[a][i] / p.density[i];
      s.last_step[k] = step;
      if (!is_free(s, i, a)) {
        p.velocity[a][i] = 0.0;
        continue;
      }
      p.velocity[a][i] = keep * p.velocity[a][i] + gain * step;
      p.displacement[a][i] += p.velocity[a][i];
      p.position[a][i] = p.reference_position[a][i] + p.displacement[a][i];
    }
  });
}
}  // namespace

void relaxation_start(ParticleStore& p, RelaxationState& s) {
  s.last_step.assign(static_cast<std::size_t>(p.dim()) * p.size(), 0.0);
  s.damping = 0.0;
  for (int a = 0; a < p.dim(); ++a) std::fill(p.velocity[a].begin(), p.velocity[a].end(), 0.0);
  advance(p, s, 0.0, 0.5);
}

double relaxation_iteration(ParticleStore& p, RelaxationState& s) {
  const double c = relaxation_damping(p, s);
  s.damping = c;
  advance(p, s, (2.0 - c) / (2.0 + c), 2.0 / (2.0 + c));
  return c;
}

}  // namespace dhpd
