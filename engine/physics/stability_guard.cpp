// Instability guard (docs/theory.md §9 stable step, §12 energy balance): checks and the message.
#include "engine/physics/stability_guard.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/base/parallel.hpp"

namespace dhpd {
namespace {

constexpr std::int64_t kBlock = 1024;  // fixed summation blocks: thread count never matters

double particle_kinetic(const ParticleStore& p, std::size_t i) {
  double v2 = 0.0;
  for (int a = 0; a < p.dim(); ++a) v2 += p.velocity[a][i] * p.velocity[a][i];
  return 0.5 * p.density[i] * p.volume[i] * v2;
}

bool finite_particle(const ParticleStore& p, std::size_t i) {
  for (int a = 0; a < p.dim(); ++a)
    if (!std::isfinite(p.velocity[a][i]) || !std::isfinite(p.displacement[a][i])) return false;
  return true;
}

/// Up to `count` particles: the non-finite ones first (lowest indices), else the largest
/// kinetic energies.
std::vector<std::size_t> culprits(const ParticleStore& p, bool non_finite, std::size_t count) {
  std::vector<std::size_t> out;
  if (non_finite) {
    for (std::size_t i = 0; i < p.size() && out.size() < count; ++i)
      if (!finite_particle(p, i)) out.push_back(i);
    if (!out.empty()) return out;
  }
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t k = std::min(count, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(),
                    [&](std::size_t a, std::size_t b) {
                      const double ka = particle_kinetic(p, a), kb = particle_kinetic(p, b);
                      return ka > kb || (ka == kb && a < b);
                    });
  order.resize(k);
  return order;
}

std::string likely_cause(const InstabilityFacts& f) {
  if (f.dt > f.critical_dt)
    return fmt::format(
        "the time step {:.6g} s is {:.3g} x the stable step {:.6g} s (time.dt with "
        "time.check_dt: false); use time.dt <= {:.6g} s or time.safety < 1",
        f.dt, f.dt / f.critical_dt, f.critical_dt, f.critical_dt);
  if (f.non_finite)
    return "a non-finite load, initial velocity or material constant, or a time step too close "
           "to the stable one; check the scene's numbers and try a smaller time.safety";
  return "energy is being created: a time step too close to the stable one (try a smaller "
         "time.safety), prescribed motion doing work the balance does not see, or a tolerance "
         "(time.energy_tolerance) too tight for this loading";
}

}  // namespace

double EnergyBudget::scale_with(double external_work) const {
  return std::max(scale, std::abs(initial) + std::abs(external_work) + std::abs(mapping));
}

void EnergyBudget::observe(double external_work) {
  scale = scale_with(external_work);
}

double EnergyBudget::allowed(double external_work) const {
  return initial + external_work + mapping + tolerance * scale_with(external_work);
}

double EnergyBudget::blow_up(double external_work, double factor) const {
  return factor * (1.0 + tolerance) * scale_with(external_work);
}

double blocked_kinetic_energy(const ParticleStore& p, std::vector<double>& block_sums) {
  const auto n = static_cast<std::int64_t>(p.size());
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  if (static_cast<std::int64_t>(block_sums.size()) < blocks)
    block_sums.resize(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t b = 0; b < blocks; ++b) {
    double sum = 0.0;
    for (std::int64_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
      sum += particle_kinetic(p, static_cast<std::size_t>(i));
    block_sums[static_cast<std::size_t>(b)] = sum;
  }
  double total = 0.0;
  for (std::int64_t b = 0; b < blocks; ++b) total += block_sums[static_cast<std::size_t>(b)];
  return total;
}

double kinetic_energy_of(const ParticleStore& p, const std::vector<std::int32_t>& particles) {
  double sum = 0.0;
  for (const auto i : particles) sum += particle_kinetic(p, static_cast<std::size_t>(i));
  return sum;
}

std::string describe_instability(const InstabilityFacts& f, const ParticleStore& p,
                                 const std::vector<double>& particle_dt,
                                 const std::vector<std::int32_t>& bond_counts) {
  std::string text =
      f.non_finite
          ? fmt::format("the state became non-finite (NaN/Inf) at step {} (t = {:.6g} s)", f.step,
                        f.time)
          : fmt::format(
                "energy growth at step {} (t = {:.6g} s): the {} is {:.6g} J, above the {:.6g} "
                "J the energy balance allows (initial + external work + refinement mapping, "
                "plus time.energy_tolerance)",
                f.step, f.time, f.measured, f.energy, f.allowed);
  text += f.non_finite ? "; first non-finite particles:" : "; most energetic particles:";
  for (const auto i : culprits(p, f.non_finite, 3)) {
    const auto x = point_of(p.reference_position, i);
    text += fmt::format(" id {} at [{}] (horizon {:.4g} m, {} bonds, own stable step {:.4g} s);",
                        p.id[i], fmt::join(x.begin(), x.begin() + p.dim(), ", "), p.horizon[i],
                        i < bond_counts.size() ? bond_counts[i] : 0,
                        i < particle_dt.size() ? particle_dt[i] : 0.0);
  }
  return text + " likely cause: " + likely_cause(f);
}

}  // namespace dhpd
