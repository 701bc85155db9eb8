// The fields of output frames: the particle store's exported fields and the derived ones.
#include "engine/output_fields.hpp"

#include <algorithm>
#include <type_traits>

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd {
namespace {

std::vector<std::int32_t> intact_own_bonds(const Simulation& sim) {
  const auto& b = sim.bonds();
  std::vector<std::int32_t> count(sim.particles().size(), 0);
  for (std::size_t i = 0; i < count.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) count[i] += b.own_intact(k) ? 1 : 0;
  return count;
}

std::vector<std::int32_t> intact_dual_bonds(const Simulation& sim) {
  const auto& b = sim.bonds();
  std::vector<std::int32_t> count(sim.particles().size(), 0);
  for (std::size_t i = 0; i < count.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) count[i] += b.dual_intact(k) ? 1 : 0;
  return count;
}

/// A quantity the engine derives for a frame (not stored per particle).
struct Derived {
  OutputField field;
  FieldValues (*values)(Simulation& sim);
};

/// The time level of each particle (docs/theory.md §19); 0 everywhere under one global step.
std::vector<std::int32_t> time_levels_of(const Simulation& sim) {
  std::vector<std::int32_t> out(sim.particles().size(), 0);
  if (const auto* t = sim.time_levels())
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = t->level[i];
  return out;
}

const Derived kDerived[] = {
    {{"strain_energy_density", "J/m^3", "strain-energy density W_i of the own bonds", false},
     [](Simulation& sim) {
       std::vector<double> w;
       strain_energy_density(sim.bonds(), sim.bond_constants(), w);
       return FieldValues{1, std::move(w)};
     }},
    {{"bond_count", "-", "intact own bonds", false},
     [](Simulation& sim) {
       return FieldValues{1, intact_own_bonds(sim)};
     }},
    {{"dual_count", "-", "intact bonds others own on the particle (its dual horizon)", false},
     [](Simulation& sim) {
       return FieldValues{1, intact_dual_bonds(sim)};
     }},
    {{"micromodulus", "N/m^6", "micromodulus C of the particle's own bonds", false},
     [](Simulation& sim) {
       return FieldValues{1, sim.micromodulus()};
     }},
    {{"critical_stretch", "1", "critical stretch s0 of the particle's own bonds", false},
     [](Simulation& sim) {
       return FieldValues{1, sim.critical_stretch()};
     }},
    {{"quadrature", "1",
      "(V_i + sum of beta V_j over the horizon) / horizon measure: 1 when integrated exactly",
      false},
     [](Simulation& sim) {
       std::vector<double> q;
       horizon_quadrature(sim.bonds(), sim.particles(), sim.setup().partial_volume,
                          sim.setup().section, q);
       return FieldValues{1, std::move(q)};
     }},
    {{"fictitious", "-",
      "1 for a particle of a fictitious boundary layer (outside the body; hide it with a "
      "threshold), 0 for the body's (written by scenes with fictitious_layer conditions)",
      false},
     [](Simulation& sim) {
       std::vector<std::int32_t> flag(sim.particles().size(), 0);
       for (const auto& layer : sim.fictitious_layers())
         for (const auto i : layer.particle) flag[static_cast<std::size_t>(i)] = 1;
       return FieldValues{1, std::move(flag)};
     }},
    {{"interaction_scale", "1",
      "multi-horizon alpha of the particle's interaction horizon, the larger of its two sides "
      "(0 outside the refinement zone and under the other models)",
      false},
     [](Simulation& sim) {
       const auto& a = sim.interaction_scale();
       std::vector<double> out(sim.particles().size(), 0.0);
       for (std::size_t i = 0; 2 * i + 1 < a.size() && i < out.size(); ++i)
         out[i] = std::max(a[2 * i], a[2 * i + 1]);
       return FieldValues{1, std::move(out)};
     }},
    {{"time_level", "-",
      "time level: the particle steps at dt0 / 2^level (written by runs with time.multirate)",
      false},
     [](Simulation& sim) {
       return FieldValues{1, time_levels_of(sim)};
     }},
};

}  // namespace

std::vector<OutputField> output_fields() {
  std::vector<OutputField> out;
  ParticleStore probe;
  for (const auto& f : probe.fields())
    if (f.output != Export::Never)
      out.push_back({f.name, f.unit, f.doc, f.output == Export::Always});
  for (const auto& d : kDerived) out.push_back(d.field);
  return out;
}

FieldValues output_values(Simulation& sim, std::string_view name) {
  if (const auto f = exported_store_field(sim.particles(), name)) {
    auto values = blank_values(*f, sim.particles().size());
    std::visit([&](auto& v) { copy_values(*f, v.data(), 0, sim.particles().size()); },
               values.values);
    return values;
  }
  for (const auto& d : kDerived)
    if (d.field.name == name) return d.values(sim);
  throw EngineError("unknown output field '" + std::string(name) + "'");
}

std::optional<FieldInfo> exported_store_field(ParticleStore& p, std::string_view name) {
  for (const auto& f : p.fields())
    if (f.output != Export::Never && f.name == name) return f;
  return std::nullopt;
}

// A store field's values: vectors interleaved (3 per particle), indices and flags as int32.
FieldValues blank_values(const FieldInfo& f, std::size_t n,
                         std::variant<std::vector<double>, std::vector<std::int32_t>> reuse) {
  return std::visit(
      [n, &reuse](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        constexpr int components = std::is_same_v<T, VectorArray> ? 3 : 1;
        using Values =
            std::conditional_t<std::is_same_v<T, VectorArray> || std::is_same_v<T, ScalarArray>,
                               std::vector<double>, std::vector<std::int32_t>>;
        Values values;
        if (auto* held = std::get_if<Values>(&reuse)) values = std::move(*held);
        values.resize(components * n);
        return FieldValues{components, std::move(values)};
      },
      f.data);
}

void copy_values(const FieldInfo& f, std::variant<double*, std::int32_t*> out, std::int64_t begin,
                 std::int64_t end) {
  std::visit(
      [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        if constexpr (std::is_same_v<T, VectorArray>) {
          double* to = std::get<double*>(out);
          for (std::int64_t i = begin; i < end; ++i)
            for (int a = 0; a < 3; ++a) to[3 * i + a] = (*data)[a][i];
        } else if constexpr (std::is_same_v<T, ScalarArray>) {
          std::copy(data->begin() + begin, data->begin() + end, std::get<double*>(out) + begin);
        } else {
          std::int32_t* to = std::get<std::int32_t*>(out);
          for (std::int64_t i = begin; i < end; ++i) to[i] = static_cast<std::int32_t>((*data)[i]);
        }
      },
      f.data);
}

}  // namespace dhpd
