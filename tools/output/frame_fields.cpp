// Per-particle output arrays, built once per frame (never in the time loop).
#include "tools/output/frame_fields.hpp"

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd::io {
namespace {

PointField vector_field(const std::string& name, const VectorArray& v) {
  std::vector<double> out(3 * v[0].size());
  for (std::size_t i = 0; i < v[0].size(); ++i)
    for (int a = 0; a < 3; ++a) out[3 * i + a] = v[a][i];
  return {name, 3, std::move(out)};
}

PointField scalar_field(const std::string& name, const std::vector<double>& s) {
  return {name, 1, s};
}

template <class T>
PointField index_field(const std::string& name, const std::vector<T>& s) {
  return {name, 1, std::vector<std::int32_t>(s.begin(), s.end())};
}

std::vector<std::int32_t> intact_own_bonds(const Simulation& sim) {
  const auto& b = sim.bonds();
  std::vector<std::int32_t> count(sim.particles().size(), 0);
  for (std::size_t i = 0; i < count.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) count[i] += b.intact[k];
  return count;
}

std::vector<std::int32_t> intact_dual_bonds(const Simulation& sim) {
  const auto& b = sim.bonds();
  const auto& d = sim.dual();
  std::vector<std::int32_t> count(sim.particles().size(), 0);
  for (std::size_t i = 0; i < count.size(); ++i)
    for (auto k = d.begin(i); k < d.end(i); ++k) count[i] += b.intact[d.bond[k]];
  return count;
}

PointField one_field(Simulation& sim, const std::string& name) {
  const auto& p = sim.particles();
  if (name == "displacement") return vector_field(name, p.displacement);
  if (name == "velocity") return vector_field(name, p.velocity);
  if (name == "force_density") return vector_field(name, p.force_density);
  if (name == "damage") return scalar_field(name, p.damage);
  if (name == "horizon") return scalar_field(name, p.horizon);
  if (name == "volume") return scalar_field(name, p.volume);
  if (name == "spacing") return scalar_field(name, p.spacing);
  if (name == "material") return index_field(name, p.material);
  if (name == "id") return index_field(name, p.id);
  if (name == "level") return index_field(name, p.level);
  if (name == "parent_id") return index_field(name, p.parent_id);
  if (name == "no_fail") return index_field(name, p.no_fail);
  if (name == "micromodulus") return scalar_field(name, sim.micromodulus());
  if (name == "critical_stretch") return scalar_field(name, sim.critical_stretch());
  if (name == "bond_count") return {name, 1, intact_own_bonds(sim)};
  if (name == "dual_count") return {name, 1, intact_dual_bonds(sim)};
  if (name == "strain_energy_density") {
    std::vector<double> w;
    strain_energy_density(sim.bonds(), p, sim.micromodulus(), w);
    return scalar_field(name, w);
  }
  if (name == "quadrature") {
    std::vector<double> q;
    horizon_quadrature(sim.bonds(), p, sim.setup().section, q);
    return scalar_field(name, q);
  }
  throw EngineError("unknown output field '" + name + "'");
}

}  // namespace

std::vector<double> frame_points(const Simulation& sim) {
  const auto& X = sim.particles().reference_position;
  std::vector<double> out(3 * X[0].size());
  for (std::size_t i = 0; i < X[0].size(); ++i)
    for (int a = 0; a < 3; ++a) out[3 * i + a] = X[a][i];
  return out;
}

std::vector<PointField> frame_fields(Simulation& sim, const std::vector<std::string>& names) {
  std::vector<PointField> out;
  out.reserve(names.size());
  for (const auto& n : names) out.push_back(one_field(sim, n));
  return out;
}

}  // namespace dhpd::io
