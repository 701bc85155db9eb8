// Time levels of multi-rate stepping (docs/theory.md §19).
#include "engine/physics/time_levels.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/base/errors.hpp"

namespace dhpd {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Levels by spacing: round(log2(h_max / h_i)), so a particle split k times is at level k.
std::vector<int> spacing_levels(const ParticleStore& p) {
  double widest = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) widest = std::max(widest, p.spacing[i]);
  std::vector<int> out(p.size(), 0);
  double last = -1.0;  // neighbouring slots mostly share a spacing: one logarithm for a run of them
  int level = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.spacing[i] != last) {
      last = p.spacing[i];
      level = std::max(0, static_cast<int>(std::lround(std::log2(widest / last))));
    }
    out[i] = level;
  }
  return out;
}

/// The smallest ℓ ≥ 0 with dt0 / 2^ℓ ≤ allowed (0 for an infinite allowance).
int step_level(double dt0, double allowed) {
  int l = 0;
  while (l < 62 && dt0 / static_cast<double>(std::int64_t{1} << l) > allowed * (1.0 + 1e-12)) ++l;
  return l;
}

/// Levels before the buffer: ℓ_i = max(spacing level, smallest ℓ with dt0/2^ℓ ≤ allowed_i).
std::vector<int> base_levels(const std::vector<int>& by_spacing, const std::vector<double>& allowed,
                             double dt0) {
  std::vector<int> out(allowed.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = std::max(by_spacing[i], step_level(dt0, allowed[i]));
  return out;
}

/// The buffer: each particle takes the finest base level among the particles it shares a bond
/// with (a one-horizon buffer around each finer level). Rows list their partners both ways, so
/// each particle above the coarsest base level raises its partners: only the finer particles'
/// rows are read.
std::vector<int> buffered(const BondRows& rows, const std::vector<int>& base) {
  std::vector<int> out(base);
  const int coarsest = base.empty() ? 0 : *std::min_element(base.begin(), base.end());
  for (std::size_t j = 0; j < base.size(); ++j) {
    const int l = base[j];
    if (l == coarsest) continue;
    for (auto k = rows.begin(j); k < rows.end(j); ++k) {
      int& raised = out[static_cast<std::size_t>(rows.other[k])];
      raised = std::max(raised, l);
    }
  }
  return out;
}

/// Whether levels evaluate fewer row entries per unit of time than one global step of
/// `one_step` by more than kLevelOverhead (docs/theory.md §19.5).
bool levels_pay(const BondRows& rows, const std::vector<int>& level, double dt0, double one_step) {
  double with_levels = 0.0, without = 0.0;
  for (std::size_t i = 0; i < level.size(); ++i) {
    const auto entries = static_cast<double>(rows.end(i) - rows.begin(i));
    with_levels += entries * std::ldexp(1.0, std::min(level[i], 60));
    without += entries;
  }
  return with_levels / dt0 * kLevelOverhead < without / one_step;
}

}  // namespace

LevelChoice choose_time_levels(const BondRows& rows, const ParticleStore& p,
                               const LevelInputs& in) {
  const std::size_t n = p.size();
  double smallest = kInfinity;
  for (const double b : in.particle_dt) smallest = std::min(smallest, b);
  // Each particle's own stable step: its bound scaled by how far the run's tight step is above
  // the smallest bound (docs/theory.md §19.1).
  const double tight = std::isfinite(smallest) ? std::max(1.0, in.critical_dt / smallest) : 1.0;
  const auto by_spacing = spacing_levels(p);
  double coarse = kInfinity;  // the coarsest spacing's stable step: a fixed dt0 may not exceed it
  for (std::size_t i = 0; i < n; ++i)
    if (by_spacing[i] == 0) coarse = std::min(coarse, tight * in.particle_dt[i]);
  LevelChoice out;
  if (!std::isfinite(coarse)) coarse = in.critical_dt;
  out.coarse_dt = coarse;
  out.dt0 = in.fixed_dt.value_or(in.safety * coarse);
  const double margin = in.fixed_dt ? 1.0 : in.safety;
  std::vector<double> allowed(n);
  for (std::size_t i = 0; i < n; ++i) allowed[i] = margin * tight * in.particle_dt[i];
  const auto level = buffered(rows, base_levels(by_spacing, allowed, out.dt0));
  out.level.resize(n);
  int finest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    finest = std::max(finest, level[i]);
    out.level[i] = static_cast<std::int8_t>(std::min(level[i], 127));
  }
  out.count = finest + 1;
  // Left to its default: one global step when the levels would not pay for their passes, or
  // would be more than the run may have (docs/theory.md §19.5).
  const double one_step = in.fixed_dt.value_or(in.safety * in.critical_dt);
  if (in.automatic && out.count > 1 &&
      (out.count > in.max_levels || !levels_pay(rows, level, out.dt0, one_step))) {
    out.level.assign(n, 0);
    out.dt0 = one_step;
    out.count = 1;
    return out;
  }
  if (out.count > in.max_levels)
    throw TimeLevelError(fmt::format(
        "the particles need {} time levels (steps dt0 / 2^0 ... dt0 / 2^{}, dt0 = {:.6g} s), more "
        "than time.max_levels = {} allows (raise it, or time.multirate: false)",
        out.count, finest, out.dt0, in.max_levels));
  return out;
}

std::vector<std::int32_t> order_by_level(const std::vector<std::int32_t>& morton,
                                         const std::vector<std::int8_t>& level) {
  std::vector<std::int32_t> out(morton);
  std::stable_sort(out.begin(), out.end(), [&](std::int32_t a, std::int32_t b) {
    return level[static_cast<std::size_t>(a)] < level[static_cast<std::size_t>(b)];
  });
  return out;
}

std::vector<std::int32_t> fewest_moves_by_level(const std::vector<std::int8_t>& level) {
  const std::size_t n = level.size();
  int levels = 0;
  for (const auto l : level) levels = std::max(levels, l + 1);
  std::vector<std::size_t> first(static_cast<std::size_t>(levels) + 1, 0);
  for (const auto l : level) ++first[static_cast<std::size_t>(l) + 1];
  for (std::size_t l = 0; l < static_cast<std::size_t>(levels); ++l) first[l + 1] += first[l];
  // holes[ℓ]: slots of block ℓ holding another level; movers[ℓ]: particles of ℓ outside it.
  std::vector<std::vector<std::int32_t>> holes(first.size()), movers(first.size());
  std::size_t block = 0;
  for (std::size_t k = 0; k < n; ++k) {
    while (k >= first[block + 1]) ++block;
    const auto l = static_cast<std::size_t>(level[k]);
    if (l == block) continue;
    holes[block].push_back(static_cast<std::int32_t>(k));
    movers[l].push_back(static_cast<std::int32_t>(k));
  }
  std::vector<std::int32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::int32_t>(k);
  for (std::size_t l = 0; l < holes.size(); ++l)
    for (std::size_t t = 0; t < holes[l].size(); ++t)
      order[static_cast<std::size_t>(holes[l][t])] = movers[l][t];
  return order;
}

std::size_t TimeLevels::bytes() const {
  std::size_t b = level.capacity() + first.capacity() * sizeof(std::int64_t);
  for (const auto& l : plans) {
    b += l.rows.capacity() * 4 + l.start.capacity() * 8 + l.count.capacity() * 4 +
         l.drift.capacity() * 4;
    for (const auto& f : l.force) b += f.capacity() * sizeof(double);
  }
  return b;
}

TimeLevels plan_time_levels(const BondRows& rows, const ParticleStore& p, LevelChoice choice) {
  const std::size_t n = p.size();
  if (!std::is_sorted(choice.level.begin(), choice.level.end()))
    throw EngineError("plan_time_levels: the particles are not sorted by level");
  TimeLevels t;
  t.dt0 = choice.dt0;
  t.coarse_dt = choice.coarse_dt;
  t.level = std::move(choice.level);
  const int levels = choice.count;
  t.first.assign(static_cast<std::size_t>(levels) + 1, static_cast<std::int64_t>(n));
  for (std::size_t i = n; i-- > 0;) t.first[static_cast<std::size_t>(t.level[i])] = i;
  for (int m = levels - 1; m >= 0; --m)
    t.first[m] = std::min(t.first[m], t.first[static_cast<std::size_t>(m) + 1]);
  t.plans.resize(static_cast<std::size_t>(levels));
  for (auto& l : t.plans) {
    l.start.assign(n, 0);
    l.count.assign(n, 0);
    for (int a = 0; a < p.dim(); ++a) l.force[a].assign(n, 0.0);
  }
  std::vector<std::int64_t> bound(static_cast<std::size_t>(levels) + 1);
  for (std::size_t i = 0; i < n; ++i) {
    const auto begin = rows.other.begin() + rows.begin(i), end = rows.other.begin() + rows.end(i);
    // bound[m]: the first entry whose neighbour is at level m or finer.
    for (int m = 0; m <= levels; ++m)
      bound[m] = rows.begin(i) + (std::lower_bound(begin, end, t.first[m]) - begin);
    const int own = t.level[i];
    int drift = own;
    for (int l = own; l < levels; ++l) {
      const std::int64_t from = l == own ? rows.begin(i) : bound[l], to = bound[l + 1];
      if (to <= from) continue;
      auto& plan = t.plans[static_cast<std::size_t>(l)];
      plan.rows.push_back(static_cast<std::int32_t>(i));
      plan.start[i] = from;
      plan.count[i] = static_cast<std::int32_t>(to - from);
      for (auto k = from; k < to; ++k) plan.own_bonds += rows.has_own(k) ? 1 : 0;
      drift = l;
    }
    t.plans[static_cast<std::size_t>(drift)].drift.push_back(static_cast<std::int32_t>(i));
  }
  return t;
}

}  // namespace dhpd
