// The resolved scene: every default written out, as YAML that reads back into the same Scene.
#include <fmt/format.h>

#include <cstdlib>

#include "engine/physics/material_law.hpp"
#include "tools/scene/detail.hpp"

namespace dhpd::scene {
namespace {

/// Shortest %g-style text that reads back to the same double (7.2e+10 rather than 72000000000).
std::string number_text(double value) {
  constexpr int kMaxDigits = 17;
  for (int digits = 1; digits < kMaxDigits; ++digits) {
    std::string text = fmt::format("{:.{}g}", value, digits);
    if (std::strtod(text.c_str(), nullptr) == value) return text;
  }
  return fmt::format("{:.{}g}", value, kMaxDigits);
}

void emit_point(YAML::Emitter& out, const geometry::Vec3& p, int dim) {
  out << YAML::Flow << YAML::BeginSeq;
  for (int a = 0; a < dim; ++a) out << number_text(p[a]);
  out << YAML::EndSeq;
}

void emit_key_point(YAML::Emitter& out, const char* key, const geometry::Vec3& p, int dim) {
  out << YAML::Key << key << YAML::Value;
  emit_point(out, p, dim);
}

void emit_region(YAML::Emitter& out, const geometry::Shape& shape, int index, int dim);

/// The entries of shape node `index` (shape word and its keys), inside a map the caller opened.
void emit_shape_entries(YAML::Emitter& out, const geometry::Shape& shape, int index, int dim) {
  using Kind = geometry::Shape::Kind;
  const auto& n = shape.node(index);
  out << YAML::Key << "shape" << YAML::Value << detail::shape_word(shape, index, dim);
  switch (n.kind) {
    case Kind::Box:
      emit_key_point(out, "min", n.a, dim);
      emit_key_point(out, "max", n.b, dim);
      break;
    case Kind::Ball:
    case Kind::Cylinder:
      emit_key_point(out, "center", n.a, dim);
      if (n.kind == Kind::Cylinder) emit_key_point(out, "axis", n.b, dim);
      out << YAML::Key << "radius" << YAML::Value << number_text(n.radius);
      if (n.kind == Kind::Cylinder)
        out << YAML::Key << "height" << YAML::Value << number_text(n.height);
      break;
    case Kind::Polygon:
      out << YAML::Key << "points" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const auto& p : n.points) emit_point(out, p, dim);
      out << YAML::EndSeq;
      break;
    case Kind::HalfSpace:
      emit_key_point(out, "point", n.a, dim);
      emit_key_point(out, "normal", n.b, dim);
      break;
    case Kind::Union:
    case Kind::Difference:
      out << YAML::Key << "of" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const int c : n.children) emit_region(out, shape, c, dim);
      out << YAML::EndSeq;
      break;
  }
}

void emit_region(YAML::Emitter& out, const geometry::Shape& shape, int index, int dim) {
  out << YAML::Flow << YAML::BeginMap;
  emit_shape_entries(out, shape, index, dim);
  out << YAML::EndMap;
}

void emit_region(YAML::Emitter& out, const geometry::Shape& shape, int dim) {
  emit_region(out, shape, shape.root(), dim);
}

void emit_materials(YAML::Emitter& out, const Scene& s) {
  const Section section{s.dimension, s.plane, s.thickness, s.area};
  out << YAML::Key << "materials" << YAML::Value << YAML::BeginMap;
  for (const auto& m : s.materials) {
    out << YAML::Key << m.name << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "E" << YAML::Value << number_text(m.law.E);
    out << YAML::Key << "rho" << YAML::Value << number_text(m.law.rho);
    out << YAML::Key << "G0" << YAML::Value << number_text(m.law.G0);
    if (s.family == ModelFamily::Bond || s.dimension > 1)  // a 1D state-based bar takes E alone
      out << YAML::Key << "nu" << YAML::Value << number_text(poisson_ratio(m.law, section));
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}

void emit_mesh(YAML::Emitter& out, const BodyPart& part, int dim) {
  out << YAML::Key << "mesh" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "size" << YAML::Value << number_text(part.mesh.size);
  if (part.graded) {
    out << YAML::Key << "grading" << YAML::Value << YAML::BeginMap << YAML::Key << "from"
        << YAML::Value;
    emit_point(out, part.mesh.from, dim);
    out << YAML::Key << "rate" << YAML::Value << number_text(part.mesh.rate) << YAML::EndMap;
  }
  out << YAML::EndMap;
}

void emit_body(YAML::Emitter& out, const Scene& s) {
  out << YAML::Key << "body" << YAML::Value << YAML::BeginSeq;
  for (const auto& part : s.body) {
    out << YAML::Flow << YAML::BeginMap;
    if (part.kind == PartKind::PointsFile) {
      out << YAML::Key << "points_file" << YAML::Value << part.points_file;
    } else {
      emit_shape_entries(out, part.shape, part.shape.root(), s.dimension);
    }
    if (part.kind == PartKind::Lattice)
      out << YAML::Key << "spacing" << YAML::Value << number_text(part.spacing);
    if (part.kind == PartKind::Mesh) emit_mesh(out, part, s.dimension);
    if (part.kind != PartKind::Lattice)
      out << YAML::Key << "point_size" << YAML::Value
          << std::string(geometry::to_string(part.point_size));
    if (!part.material.empty()) out << YAML::Key << "material" << YAML::Value << part.material;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (s.material_regions.empty()) return;
  out << YAML::Key << "material_regions" << YAML::Value << YAML::BeginSeq;
  for (const auto& r : s.material_regions) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "region" << YAML::Value;
    emit_region(out, r.region, s.dimension);
    out << YAML::Key << "material" << YAML::Value << r.material << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void emit_cracks_and_no_fail(YAML::Emitter& out, const Scene& s) {
  if (!s.cracks.empty()) {
    out << YAML::Key << "cracks" << YAML::Value << YAML::BeginSeq;
    for (const auto& c : s.cracks) {
      out << YAML::Flow << YAML::BeginSeq;
      for (const auto& p : c.crack.points) emit_point(out, p, s.dimension);
      out << YAML::EndSeq;
    }
    out << YAML::EndSeq;
  }
  if (!s.no_fail.empty()) {
    out << YAML::Key << "no_fail" << YAML::Value << YAML::BeginSeq;
    for (const auto& r : s.no_fail) emit_region(out, r.shape, s.dimension);
    out << YAML::EndSeq;
  }
}

void emit_optional_point(YAML::Emitter& out, const char* key, const std::optional<Vec3>& p,
                         int dim) {
  if (!p) return;
  out << YAML::Key << key << YAML::Value;
  emit_point(out, *p, dim);
}

void emit_initial_conditions(YAML::Emitter& out, const Scene& s) {
  if (s.initial_conditions.empty()) return;
  const int dim = s.dimension;
  out << YAML::Key << "initial_conditions" << YAML::Value << YAML::BeginSeq;
  for (const auto& item : s.initial_conditions) {
    const InitialCondition& ic = item.ic;
    out << YAML::BeginMap << YAML::Key << "region" << YAML::Value;
    emit_region(out, ic.region, dim);
    emit_optional_point(out, "velocity", ic.velocity, dim);
    emit_optional_point(out, "displacement", ic.displacement, dim);
    emit_optional_point(out, "strain", ic.strain, dim);
    emit_optional_point(out, "origin", ic.origin, dim);
    if (ic.gaussian_width) {
      out << YAML::Key << "gaussian" << YAML::Value << YAML::Flow << YAML::BeginMap;
      emit_optional_point(out, "center", ic.gaussian_center, dim);
      out << YAML::Key << "width" << YAML::Value << number_text(*ic.gaussian_width);
      if (ic.gaussian_axis >= 0)
        out << YAML::Key << "axis" << YAML::Value << std::string(1, "xyz"[ic.gaussian_axis]);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void emit_boundary_condition(YAML::Emitter& out, const BoundaryCondition& bc, int dim) {
  const auto axes = detail::axis_names(dim);
  out << YAML::BeginMap;
  if (bc.layer_axis >= 0) {
    out << YAML::Key << "fictitious_layer" << YAML::Value
        << axes[bc.layer_axis] + (bc.layer_side > 0 ? "_max" : "_min");
  } else {
    out << YAML::Key << "region" << YAML::Value;
    emit_region(out, bc.region, dim);
  }
  switch (bc.kind) {
    case BoundaryCondition::Kind::Velocity:
    case BoundaryCondition::Kind::Displacement: {
      const bool velocity = bc.kind == BoundaryCondition::Kind::Velocity;
      const auto& held = velocity ? bc.velocity : bc.displacement;
      out << YAML::Key << (velocity ? "velocity" : "displacement") << YAML::Value << YAML::Flow
          << YAML::BeginMap;
      for (int a = 0; a < dim; ++a) {
        if (!held[a]) continue;
        out << YAML::Key << axes[a] << YAML::Value;
        if (bc.in_time[a].empty()) {
          out << number_text(*held[a]);
          continue;
        }
        out << YAML::BeginMap << YAML::Key << "table" << YAML::Value << YAML::BeginSeq;
        for (const auto& [t, v] : bc.in_time[a].points)
          out << YAML::BeginSeq << number_text(t) << number_text(v) << YAML::EndSeq;
        out << YAML::EndSeq << YAML::EndMap;
      }
      out << YAML::EndMap;
      break;
    }
    case BoundaryCondition::Kind::Fixed:
      out << YAML::Key << "fixed" << YAML::Value << true;
      break;
    case BoundaryCondition::Kind::Traction:
      emit_optional_point(out, "traction", bc.traction, dim);
      if (bc.layer_axis < 0) out << YAML::Key << "normal" << YAML::Value << axes[bc.normal_axis];
      break;
  }
  out << YAML::EndMap;
}

void emit_time(YAML::Emitter& out, const TimeSpec& time) {
  out << YAML::Key << "time" << YAML::Value << YAML::BeginMap;
  if (time.end) out << YAML::Key << "end" << YAML::Value << number_text(*time.end);
  if (time.steps) out << YAML::Key << "steps" << YAML::Value << *time.steps;
  out << YAML::Key << "safety" << YAML::Value << number_text(time.safety);
  if (time.dt) out << YAML::Key << "dt" << YAML::Value << number_text(*time.dt);
  out << YAML::Key << "check_dt" << YAML::Value << time.check_dt;
  out << YAML::Key << "stable_step" << YAML::Value
      << (time.stable_step == StableStepEstimate::Lanczos ? "lanczos" : "bound");
  out << YAML::Key << "energy_tolerance" << YAML::Value << number_text(time.energy_tolerance);
  if (time.multirate) out << YAML::Key << "multirate" << YAML::Value << *time.multirate;
  out << YAML::Key << "max_levels" << YAML::Value << time.max_levels;
  out << YAML::EndMap;
}

void emit_solver(YAML::Emitter& out, const Scene& s) {
  out << YAML::Key << "solver" << YAML::Value;
  if (!s.statics) {
    out << "dynamic";
    return;
  }
  const auto& solver = *s.statics;
  out << YAML::Flow << YAML::BeginMap << YAML::Key << "type" << YAML::Value << "static" << YAML::Key
      << "tolerance" << YAML::Value << number_text(solver.tolerance) << YAML::Key
      << "max_iterations" << YAML::Value << solver.max_iterations << YAML::Key << "safety"
      << YAML::Value << number_text(solver.safety) << YAML::Key << "max_break_rounds" << YAML::Value
      << solver.max_break_rounds << YAML::Key << "trace_every" << YAML::Value << solver.trace_every
      << YAML::EndMap;
}

void emit_output(YAML::Emitter& out, const OutputSpec& output, int dim) {
  out << YAML::Key << "output" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "directory" << YAML::Value << output.directory;
  if (output.every) out << YAML::Key << "every" << YAML::Value << *output.every;
  if (output.frames) out << YAML::Key << "frames" << YAML::Value << *output.frames;
  out << YAML::Key << "fields" << YAML::Value << YAML::Flow << output.fields;
  out << YAML::Key << "history_every" << YAML::Value << output.history_every;
  if (output.checkpoint_every)
    out << YAML::Key << "checkpoint_every" << YAML::Value << *output.checkpoint_every;
  out << YAML::Key << "checkpoint_minutes" << YAML::Value << number_text(output.checkpoint_minutes);
  out << YAML::Key << "compression" << YAML::Value << output.compression;
  if (!output.probes.empty()) {
    out << YAML::Key << "probes" << YAML::Value << YAML::BeginSeq;
    for (const auto& probe : output.probes) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << probe.name;
      emit_key_point(out, "at", probe.at, dim);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (!output.sections.empty()) {
    const auto axes = detail::axis_names(dim);
    out << YAML::Key << "sections" << YAML::Value << YAML::BeginSeq;
    for (const auto& section : output.sections)
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << section.name
          << YAML::Key << "axis" << YAML::Value << axes[section.axis] << YAML::Key << "at"
          << YAML::Value << number_text(section.at) << YAML::EndMap;
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
}

void emit_effects(YAML::Emitter& out, const Scene& s) {
  out << YAML::Key << "effects" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "fracture" << YAML::Value << s.effects.fracture;
  out << YAML::Key << "refinement" << YAML::Value;
  if (!s.refinement) {
    out << false << YAML::EndMap;
    return;
  }
  const auto& r = s.refinement->settings;
  out << YAML::BeginMap;
  if (r.trigger.any()) {
    out << YAML::Key << "trigger" << YAML::Value << YAML::Flow << YAML::BeginMap;
    if (r.trigger.damage)
      out << YAML::Key << "damage" << YAML::Value << number_text(*r.trigger.damage);
    if (r.trigger.energy)
      out << YAML::Key << "energy" << YAML::Value << number_text(*r.trigger.energy);
    if (r.trigger.stretch)
      out << YAML::Key << "stretch" << YAML::Value << number_text(*r.trigger.stretch);
    if (r.trigger.near_crack)
      out << YAML::Key << "near_crack" << YAML::Value << number_text(*r.trigger.near_crack);
    if (r.trigger.near_precrack)
      out << YAML::Key << "near_precrack" << YAML::Value << number_text(*r.trigger.near_precrack);
    out << YAML::EndMap;
  }
  out << YAML::Key << "buffer" << YAML::Value << number_text(r.buffer);
  out << YAML::Key << "max_level" << YAML::Value << r.max_level;
  out << YAML::Key << "check_every" << YAML::Value << r.check_every;
  out << YAML::Key << "mapping" << YAML::Value << refine::mapping_name(r.mapping);
  for (const auto& [key, shapes] : {std::pair{"zones", &r.zones}, std::pair{"within", &r.within}}) {
    if (shapes->empty()) continue;
    out << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (const auto& z : *shapes) emit_region(out, z, s.dimension);
    out << YAML::EndSeq;
  }
  out << YAML::EndMap << YAML::EndMap;
}

void emit_published(YAML::Emitter& out, const measure::Published& v) {
  using Kind = measure::Published::Kind;
  switch (v.kind) {
    case Kind::Number:
      out << (v.integer ? fmt::format("{}", static_cast<std::int64_t>(v.number))
                        : number_text(v.number));
      break;
    case Kind::List:
      out << YAML::Flow << YAML::BeginSeq;
      for (const double d : v.list) out << number_text(d);
      out << YAML::EndSeq;
      break;
    case Kind::Map:
      out << YAML::BeginMap;
      for (std::size_t k = 0; k < v.keys.size(); ++k) {
        out << YAML::Key << v.keys[k] << YAML::Value;
        emit_published(out, v.values[k]);
      }
      out << YAML::EndMap;
      break;
  }
}

void emit_measure(YAML::Emitter& out, const Scene& s) {
  if (!s.measure) return;
  const auto& m = s.measure->settings;
  out << YAML::Key << "measure" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "damage_threshold" << YAML::Value << number_text(m.damage_threshold);
  out << YAML::Key << "every" << YAML::Value << m.every;
  out << YAML::Key << "smoothing" << YAML::Value << m.smoothing;
  out << YAML::Key << "branch_separation" << YAML::Value << number_text(m.branch_separation);
  out << YAML::Key << "tips" << YAML::Value << YAML::BeginSeq;
  for (const auto& tip : m.tips) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << tip.name;
    emit_key_point(out, "at", tip.at, s.dimension);
    emit_key_point(out, "direction", tip.direction, s.dimension);
    if (tip.front) emit_key_point(out, "front", *tip.front, s.dimension);
    if (tip.region) {
      out << YAML::Key << "region" << YAML::Value;
      emit_region(out, *tip.region, s.dimension);
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (s.measure->published) {
    out << YAML::Key << "published" << YAML::Value;
    emit_published(out, *s.measure->published);
  }
  out << YAML::EndMap;
}

}  // namespace

std::string resolved_yaml(const Scene& s) {
  YAML::Emitter out;
  out.SetBoolFormat(YAML::TrueFalseBool);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << s.name;
  out << YAML::Key << "dimension" << YAML::Value << s.dimension;
  if (s.dimension == 2) {
    out << YAML::Key << "plane" << YAML::Value << std::string(to_string(s.plane));
    out << YAML::Key << "thickness" << YAML::Value << number_text(s.thickness);
  }
  if (s.dimension == 1) out << YAML::Key << "area" << YAML::Value << number_text(s.area);
  emit_materials(out, s);
  emit_body(out, s);
  out << YAML::Key << "horizon" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "factor" << YAML::Value << number_text(s.horizon_factor) << YAML::EndMap;
  out << YAML::Key << "model" << YAML::Value;
  if (s.family == ModelFamily::Bond) {
    out << std::string(to_string(s.model));
  } else {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "family" << YAML::Value
        << std::string(to_string(s.family)) << YAML::Key << "horizon" << YAML::Value
        << std::string(to_string(s.model)) << YAML::Key << "influence" << YAML::Value
        << std::string(to_string(s.influence));
    if (s.family == ModelFamily::OrdinaryState)
      out << YAML::Key << "surface_correction" << YAML::Value << s.surface_correction;
    out << YAML::EndMap;
  }
  out << YAML::Key << "partial_volume" << YAML::Value << std::string(to_string(s.partial_volume));
  out << YAML::Key << "interfaces" << YAML::Value
      << (consistent_interfaces(s) ? "consistent" : "paper");
  emit_cracks_and_no_fail(out, s);
  emit_initial_conditions(out, s);
  if (!s.boundary_conditions.empty()) {
    out << YAML::Key << "boundary_conditions" << YAML::Value << YAML::BeginSeq;
    for (const auto& bc : s.boundary_conditions) emit_boundary_condition(out, bc.bc, s.dimension);
    out << YAML::EndSeq;
  }
  emit_effects(out, s);
  emit_solver(out, s);
  emit_time(out, s.time);
  emit_output(out, s.output, s.dimension);
  emit_measure(out, s);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace dhpd::scene
