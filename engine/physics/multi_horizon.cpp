// Multi-horizon peridynamics (CMES 2019 §2, eqs. 1–7; docs/theory.md §24).
#include "engine/physics/multi_horizon.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/base/errors.hpp"

namespace dhpd {

namespace {

double x_of(const ParticleStore& p, std::size_t i) {
  return p.reference_position[0][i];
}

}  // namespace

void for_each_coarser_overlap(const ParticleStore& p, const CoarserOverlap& visit) {
  // Sorted by x, each horizon scanned out to its radius plus the largest half-cell.
  const auto& x = p.reference_position[0];
  std::vector<std::size_t> order(p.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&x](auto a, auto b) { return x[a] < x[b]; });
  std::vector<double> sorted(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = x[order[k]];
  const double half = 0.5 * *std::max_element(p.spacing.begin(), p.spacing.end());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double reach = p.horizon[i] + half;
    auto k = static_cast<std::size_t>(std::lower_bound(sorted.begin(), sorted.end(), x[i] - reach) -
                                      sorted.begin());
    for (; k < sorted.size() && sorted[k] <= x[i] + reach; ++k) {
      const auto j = order[k];
      if (j == i || !coarser(p, j, i)) continue;
      // j's cell as distances from x_i, cut to i's horizon on j's side.
      const double near = std::abs(x[j] - x[i]) - 0.5 * p.spacing[j];
      const double r0 = std::max(0.0, near), r1 = std::min(p.horizon[i], near + p.spacing[j]);
      if (r1 > r0) visit(i, side_of(p, i, j), r0, r1);
    }
  }
}

namespace {

/// Per particle and side, the length of its natural horizon that coarser cells occupy.
std::vector<double> occupied_by_coarser(const ParticleStore& p) {
  std::vector<double> occupied(2 * p.size(), 0.0);
  for_each_coarser_overlap(p, [&occupied](std::size_t i, std::size_t side, double r0, double r1) {
    occupied[2 * i + side] += r1 - r0;
  });
  return occupied;
}

}  // namespace

std::vector<double> interaction_scales(const BondRows& b, const ParticleStore& p,
                                       const std::vector<double>& C) {
  if (p.dim() != 1)
    throw MultiHorizonError(
        "model multi-horizon is defined in 1D only: in 2D and 3D eq. 7 of CMES 2019 asks one "
        "scalar α per interaction horizon to match a vector integral, which fixes it for no "
        "interface but a straight one (docs/theory.md §24)");
  const auto occupied = occupied_by_coarser(p);
  std::vector<double> alpha(2 * p.size(), 0.0);
  std::size_t refined = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::array<double, 2> weight{0.0, 0.0};  // Σ (C_i + C_j) ℓ_j over the interaction horizon
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      const auto j = static_cast<std::size_t>(b.other[k]);
      if (coarser(p, j, i) && (b.flags[k] & kDual))
        weight[side_of(p, i, j)] += (C[i] + C[j]) * p.spacing[j];
    }
    for (std::size_t side = 0; side < 2; ++side) {
      const double filled = occupied[2 * i + side];
      if (weight[side] > 0.0) {
        alpha[2 * i + side] = 2.0 * C[i] * filled / weight[side];
      } else if (filled > 1e-9 * p.spacing[i]) {
        throw MultiHorizonError(fmt::format(
            "model multi-horizon: α of the particle at x = {:.6g} m is undefined: coarser "
            "particles fill {:.3g} m of its horizon toward {}x, but none of them includes it "
            "(an empty interaction horizon; eq. 7 has nothing to scale)",
            x_of(p, i), filled, side ? "+" : "−"));
      }
    }
    refined += weight[0] + weight[1] > 0.0 ? 1 : 0;
  }
  if (refined == 0)
    throw MultiHorizonError(
        "model multi-horizon needs a refinement zone: particles whose horizon a coarser "
        "particle's horizon reaches beyond (body parts of different spacing); with one horizon "
        "everywhere use model constant-horizon");
  return alpha;
}

double multi_horizon_stiffness(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                               const std::vector<double>& C, const std::vector<double>& alpha,
                               std::size_t i, std::int64_t k) {
  const auto j = static_cast<std::size_t>(b.other[k]);
  const auto f = b.flags[k];
  const double length = b.length(k);
  if (coarser(p, j, i))  // i's interaction horizon: α_i (T − T′), j's own bond on i
    return (f & kDualIntact) ? alpha[2 * i + side_of(p, i, j)] * (C[i] + C[j]) : 0.0;
  // i's natural horizon: i's state, and j's — scaled by α_j where i is in j's interaction
  // horizon (j finer), j's natural state otherwise.
  double K = (f & kOwnIntact) ? C[i] * bond_weight(p, rule, i, j, length) : 0.0;
  if (coarser(p, i, j))
    K += (f & kOwnIntact) ? alpha[2 * j + side_of(p, j, i)] * C[j] : 0.0;
  else if (f & kDualIntact)
    K += C[j] * bond_weight(p, rule, j, i, length);
  return K;
}

}  // namespace dhpd
