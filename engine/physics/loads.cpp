// Initial and boundary conditions. A traction t on a layer of depth d becomes b = t/d, so the total
// force equals t × (loaded face area) on a lattice: a body force on a boundary layer inside the
// body, not the fictitious-layer treatment of the papers (no particles outside the body).
#include "engine/physics/loads.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "engine/base/errors.hpp"

namespace dhpd {

std::vector<std::int32_t> select(const ParticleStore& p, const geometry::Shape& region) {
  std::vector<std::int32_t> out;
  const auto& X = p.reference_position;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (region.contains({X[0][i], X[1][i], X[2][i]}, p.dim()))
      out.push_back(static_cast<std::int32_t>(i));
  return out;
}

void apply_initial_condition(const InitialCondition& ic, ParticleStore& p) {
  const auto& X = p.reference_position;
  for (const auto i : select(p, ic.region)) {
    double envelope = 1.0;
    if (ic.gaussian_width) {
      double r2 = 0.0;
      for (int a = 0; a < p.dim(); ++a)
        if (ic.gaussian_axis < 0 || a == ic.gaussian_axis)
          r2 += std::pow(X[a][i] - ic.gaussian_center[a], 2);
      envelope = std::exp(-r2 / (*ic.gaussian_width * *ic.gaussian_width));
    }
    for (int a = 0; a < p.dim(); ++a) {
      if (ic.velocity) p.velocity[a][i] += envelope * (*ic.velocity)[a];
      if (ic.displacement) p.displacement[a][i] += envelope * (*ic.displacement)[a];
      if (ic.strain) p.displacement[a][i] += (*ic.strain)[a] * (X[a][i] - ic.origin[a]);
    }
  }
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < p.size(); ++i) p.position[a][i] = X[a][i] + p.displacement[a][i];
}

namespace {
double layer_depth(const ParticleStore& p, const std::vector<std::int32_t>& layer, int axis) {
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const auto i : layer) {
    lo = std::min(lo, p.reference_position[axis][i] - 0.5 * p.spacing[i]);
    hi = std::max(hi, p.reference_position[axis][i] + 0.5 * p.spacing[i]);
  }
  return hi - lo;
}
}  // namespace

namespace {
/// Which components a velocity or fixed condition prescribes, and to what.
void prescribe(ResolvedLoads& r, const BoundaryCondition& bc, std::size_t c, std::int32_t i,
               int dim) {
  std::array<std::uint8_t, 3> m{0, 0, 0};
  Vec3 v{0, 0, 0}, u{0, 0, 0};
  for (int a = 0; a < std::min(dim, 3); ++a) {
    const bool fixed = bc.kind == BoundaryCondition::Kind::Fixed;
    if (fixed || bc.velocity[a]) m[a] = 1, v[a] = fixed ? 0.0 : *bc.velocity[a];
    if (bc.displacement[a]) m[a] = kHeldAt, u[a] = *bc.displacement[a];
  }
  r.prescribed.push_back(i);
  r.mask.push_back(m);
  r.prescribed_velocity.push_back(v);
  r.prescribed_displacement.push_back(u);
  r.condition.push_back(static_cast<std::int32_t>(c));
}

void add_entry(ResolvedLoads& r, const BoundaryCondition& bc, std::size_t c, std::int32_t i,
               int dim) {
  if (bc.kind == BoundaryCondition::Kind::Traction) {
    r.loaded.push_back(i);
    r.body_force.push_back(r.condition_body_force[c]);
  } else {
    prescribe(r, bc, c, i, dim);
  }
}
}  // namespace

ResolvedLoads resolve_loads(const std::vector<BoundaryCondition>& bcs, const ParticleStore& p) {
  ResolvedLoads r;
  r.condition_body_force.assign(bcs.size(), Vec3{0, 0, 0});
  for (std::size_t c = 0; c < bcs.size(); ++c) {
    const auto& bc = bcs[c];
    if (bc.layer_axis >= 0) continue;  // a fictitious layer (Simulation holds its particles)
    const auto chosen = select(p, bc.region);
    if (chosen.empty())
      throw InputError("boundary_conditions." + std::to_string(c) +
                       ".region: selects no particle (the region lies outside the body)");
    if (bc.kind == BoundaryCondition::Kind::Traction) {
      const double depth = layer_depth(p, chosen, bc.normal_axis);
      r.condition_body_force[c] = {bc.traction[0] / depth, bc.traction[1] / depth,
                                   bc.traction[2] / depth};
    }
    for (const auto i : chosen) add_entry(r, bc, c, i, p.dim());
  }
  return r;
}

void inherit_loads(ResolvedLoads& r, const std::vector<std::int32_t>& successor,
                   const std::vector<std::int32_t>& predecessor) {
  std::vector<std::int32_t> givers(predecessor);
  std::sort(givers.begin(), givers.end());
  givers.erase(std::unique(givers.begin(), givers.end()), givers.end());
  // The givers' entries by slot: (slot, entry index).
  auto entries_of_givers = [&](const std::vector<std::int32_t>& list) {
    std::vector<std::pair<std::int32_t, std::size_t>> out;
    for (std::size_t k = 0; k < list.size(); ++k)
      if (std::binary_search(givers.begin(), givers.end(), list[k])) out.emplace_back(list[k], k);
    std::sort(out.begin(), out.end());
    return out;
  };
  const auto loaded = entries_of_givers(r.loaded);
  const auto held = entries_of_givers(r.prescribed);
  for (std::size_t c = 0; c < successor.size(); ++c) {
    if (successor[c] == predecessor[c]) continue;
    const std::pair<std::int32_t, std::size_t> from{predecessor[c], 0};
    for (auto e = std::lower_bound(loaded.begin(), loaded.end(), from);
         e != loaded.end() && e->first == predecessor[c]; ++e) {
      r.loaded.push_back(successor[c]);
      r.body_force.push_back(r.body_force[e->second]);
    }
    for (auto e = std::lower_bound(held.begin(), held.end(), from);
         e != held.end() && e->first == predecessor[c]; ++e) {
      r.prescribed.push_back(successor[c]);
      r.mask.push_back(r.mask[e->second]);
      r.prescribed_velocity.push_back(r.prescribed_velocity[e->second]);
      r.prescribed_displacement.push_back(r.prescribed_displacement[e->second]);
      r.condition.push_back(r.condition[e->second]);
    }
  }
}

void renumber_loads(ResolvedLoads& r, const std::vector<std::int32_t>& new_index) {
  for (auto& i : r.loaded) i = new_index[static_cast<std::size_t>(i)];
  for (auto& i : r.prescribed) i = new_index[static_cast<std::size_t>(i)];
}

double TimeFunction::at(double t) const {
  if (t <= points.front().first) return points.front().second;
  if (t >= points.back().first) return points.back().second;
  const auto next = std::upper_bound(points.begin(), points.end(), t,
                                     [](double x, const auto& q) { return x < q.first; });
  const auto& [t1, v1] = *next;
  const auto& [t0, v0] = *(next - 1);
  return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
}

namespace {
/// The function of time of entry k's component a, or null.
const TimeFunction* function_of(const ResolvedLoads& loads,
                                const std::vector<BoundaryCondition>& conditions, std::size_t k,
                                int a) {
  const auto c = loads.condition[k];
  if (c < 0) return nullptr;
  const auto& f = conditions[static_cast<std::size_t>(c)].in_time[a];
  return f.empty() ? nullptr : &f;
}
}  // namespace

void apply_prescribed_displacement(const ResolvedLoads& loads,
                                   const std::vector<BoundaryCondition>& conditions, double factor,
                                   double time, ParticleStore& p) {
  for (std::size_t k = 0; k < loads.prescribed.size(); ++k) {
    const auto i = static_cast<std::size_t>(loads.prescribed[k]);
    for (int a = 0; a < p.dim(); ++a) {
      if (loads.mask[k][a] != kHeldAt) continue;
      const auto* f = function_of(loads, conditions, k, a);
      p.displacement[a][i] = f ? f->at(time) : factor * loads.prescribed_displacement[k][a];
      p.position[a][i] = p.reference_position[a][i] + p.displacement[a][i];
    }
  }
}

void update_prescribed_velocity(ResolvedLoads& loads,
                                const std::vector<BoundaryCondition>& conditions, double t,
                                double dt) {
  for (std::size_t k = 0; k < loads.prescribed.size(); ++k)
    for (int a = 0; a < 3; ++a) {
      const auto* f = loads.mask[k][a] ? function_of(loads, conditions, k, a) : nullptr;
      if (!f) continue;
      loads.prescribed_velocity[k][a] =
          loads.mask[k][a] == kHeldAt ? (f->at(t + dt) - f->at(t)) / dt : f->at(t + 0.5 * dt);
    }
}

Vec3 reaction_force(const ResolvedLoads& loads, const ParticleStore& p, std::int32_t condition) {
  Vec3 r{0, 0, 0};
  for (std::size_t k = 0; k < loads.prescribed.size(); ++k) {
    if (loads.condition[k] != condition) continue;
    const auto i = static_cast<std::size_t>(loads.prescribed[k]);
    for (int a = 0; a < p.dim(); ++a)
      if (loads.mask[k][a]) r[a] -= p.volume[i] * p.force_density[a][i];
  }
  return r;
}

std::vector<std::uint8_t> prescribed_axes(const ResolvedLoads& loads, std::size_t n) {
  std::vector<std::uint8_t> fixed(n, 0);
  for (std::size_t k = 0; k < loads.prescribed.size(); ++k)
    for (int a = 0; a < 3; ++a)
      if (loads.mask[k][a]) fixed[static_cast<std::size_t>(loads.prescribed[k])] |= 1u << a;
  return fixed;
}

}  // namespace dhpd
