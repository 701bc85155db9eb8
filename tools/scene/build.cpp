// Scene → SimulationSetup → Simulation, with the checks that need particles.
#include "tools/scene/build.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/discretization/neighbor_search.hpp"
#include "engine/physics/bond_loops.hpp"
#include "geometry/mesh_points.hpp"
#include "geometry/point_checks.hpp"
#include "tools/scene/points_file.hpp"

namespace dhpd::scene {
namespace {

int material_index(const Scene& s, const std::string& name, const Location& where) {
  for (std::size_t k = 0; k < s.materials.size(); ++k)
    if (s.materials[k].name == name) return static_cast<int>(k);
  fail(where, fmt::format("material '{}' is not defined", name));
}

bool selects_any(const geometry::PointSet& pts, const geometry::Shape& region, int dim) {
  return std::any_of(pts.position.begin(), pts.position.end(),
                     [&](const geometry::Vec3& x) { return region.contains(x, dim); });
}

void require_particles(const geometry::PointSet& pts, const geometry::Shape& region, int dim,
                       const Location& where) {
  if (!selects_any(pts, region, dim))
    fail({where.file, where.line, where.path + ".region"},
         "selects no particle: the region lies outside the body (or between particles)");
}

/// The particles of one part, before later parts replace those inside their shapes.
geometry::PointSet part_points(const Scene& s, std::size_t p) {
  const BodyPart& part = s.body[p];
  const int index = static_cast<int>(p);
  const int material = part.material.empty() ? 0 : material_index(s, part.material, part.where);
  if (part.kind == PartKind::Lattice) {
    auto pts = geometry::fill_lattice({{part.shape, part.spacing, material}}, s.dimension);
    std::fill(pts.part.begin(), pts.part.end(), index);
    return pts;
  }
  if (part.kind == PartKind::Mesh)
    return geometry::mesh_box(part.shape.bounds(s.dimension), s.dimension, part.mesh, material,
                              index, part.point_size);
  PointsFileOptions options;
  options.dim = s.dimension;
  options.section = s.dimension == 2 ? s.thickness : (s.dimension == 1 ? s.area : 1.0);
  for (const auto& m : s.materials) options.materials.push_back(m.name);
  if (!part.material.empty()) options.default_material = material;
  options.part = index;
  options.size_rule = part.point_size;
  return read_points_file(part.points_file, options);
}

/// Points that would make the run unstable are refused at load time, naming their part.
void check_points(const Scene& s, const geometry::PointSet& pts) {
  const int dim = s.dimension;
  if (const auto i = geometry::first_degenerate_point(pts))
    fail(s.body[static_cast<std::size_t>(pts.part[*i])].where,
         fmt::format("the particle at {} has cell measure {} and spacing {}: a particle needs a "
                     "positive volume and spacing",
                     point_text(pts.position[*i], dim), pts.cell_measure[*i], pts.spacing[*i]),
         "cell measure > 0 and spacing > 0 for every particle");
  if (const auto pair = geometry::first_coincident_pair(pts, dim)) {
    const auto [i, j] = *pair;
    const auto& where = s.body[static_cast<std::size_t>(pts.part[j])].where;
    fail(where,
         fmt::format("two particles coincide at {} (part {} and part {}): a bond needs a length",
                     point_text(pts.position[j], dim), pts.part[i] + 1, pts.part[j] + 1),
         "particles at distinct positions (closer than 1e-6 of their spacing counts as one place)");
  }
}

}  // namespace

std::string point_text(const geometry::Vec3& x, int dim) {
  return fmt::format("[{}]", fmt::join(x.begin(), x.begin() + dim, ", "));
}

/// Every part's particles in order; a point inside a later lattice or mesh part's shape is
/// dropped (that part wins).
geometry::PointSet body_points(const Scene& s) {
  geometry::PointSet out;
  for (std::size_t p = 0; p < s.body.size(); ++p) {
    const auto pts = part_points(s, p);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      bool overridden = false;
      for (std::size_t q = p + 1; q < s.body.size() && !overridden; ++q)
        overridden = s.body[q].kind != PartKind::PointsFile &&
                     s.body[q].shape.contains(pts.position[i], s.dimension);
      if (overridden) continue;
      out.position.push_back(pts.position[i]);
      out.cell_measure.push_back(pts.cell_measure[i]);
      out.spacing.push_back(pts.spacing[i]);
      out.material.push_back(pts.material[i]);
      out.part.push_back(pts.part[i]);
    }
  }
  return out;
}

bool consistent_interfaces(const Scene& s) {
  if (s.interfaces) return *s.interfaces;
  return s.model == ForceModel::DualHorizon && s.family != ModelFamily::Correspondence &&
         std::all_of(s.body.begin(), s.body.end(),
                     [](const BodyPart& p) { return p.kind == PartKind::Lattice; });
}

SimulationSetup build_setup(const Scene& s) {
  SimulationSetup setup;
  setup.section.dim = s.dimension;
  setup.section.plane = s.plane;
  setup.section.thickness = s.thickness;
  setup.section.area = s.area;
  setup.model = s.model;
  setup.family = s.family;
  setup.influence = s.influence;
  setup.surface_correction = s.surface_correction;
  setup.partial_volume = s.partial_volume;
  setup.interface_correction = consistent_interfaces(s);
  setup.horizon_factor = s.horizon_factor;
  for (const auto& m : s.materials) setup.materials.push_back(m.law);
  setup.points = body_points(s);
  check_points(s, setup.points);
  for (std::size_t p = 0; p < s.body.size(); ++p)
    if (std::find(setup.points.part.begin(), setup.points.part.end(), static_cast<int>(p)) ==
        setup.points.part.end())
      fail(s.body[p].where, part_points(s, p).size() == 0
                                ? "this part's shape holds no lattice point (the shape is empty "
                                  "or thinner than the spacing)"
                                : "this part adds no particle: later parts cover all of it");
  std::vector<geometry::MaterialRegion> regions;
  for (const auto& r : s.material_regions)
    regions.push_back({r.region, material_index(s, r.material, r.where)});
  const auto selected = geometry::assign_materials(setup.points, regions, s.dimension);
  for (std::size_t r = 0; r < selected.size(); ++r)
    if (selected[r] == 0)
      require_particles(setup.points, s.material_regions[r].region, s.dimension,
                        s.material_regions[r].where);
  for (const auto& c : s.cracks) setup.cracks.push_back(c.crack);
  for (const auto& r : s.no_fail) {
    if (!selects_any(setup.points, r.shape, s.dimension))
      fail(r.where, "selects no particle: the region lies outside the body");
    setup.no_fail.push_back(r.shape);
  }
  for (const auto& ic : s.initial_conditions) {
    require_particles(setup.points, ic.ic.region, s.dimension, ic.where);
    setup.initial_conditions.push_back(ic.ic);
  }
  for (const auto& bc : s.boundary_conditions) {
    if (bc.bc.layer_axis < 0) require_particles(setup.points, bc.bc.region, s.dimension, bc.where);
    setup.boundary_conditions.push_back(bc.bc);
  }
  // Mirrored from the body alone, after every region selected its particles.
  const auto body = setup.points;
  for (std::size_t k = 0; k < s.boundary_conditions.size(); ++k)
    if (s.boundary_conditions[k].bc.layer_axis >= 0)
      setup.layers.push_back(fictitious_layer(s, k, body, setup.points));
  setup.effects = s.effects;
  setup.effects.refinement = s.refinement.has_value();
  // The body is the union of its lattice parts' shapes: children outside it are not created.
  // (Refinement refuses meshed and points-file parts, so lattice parts are all that matter.)
  std::vector<geometry::Shape> shapes;
  for (const auto& part : s.body)
    if (part.kind == PartKind::Lattice) shapes.push_back(part.shape);
  if (!shapes.empty())
    setup.body = shapes.size() == 1 ? shapes.front() : geometry::Shape::union_of(shapes);
  setup.safety = s.time.safety;
  setup.stable_step = s.time.stable_step;
  setup.fixed_dt = s.time.dt;
  setup.energy_tolerance = s.time.energy_tolerance;
  setup.statics = s.statics;
  if (s.statics) setup.load_steps = s.time.steps.value_or(1);
  setup.multirate = s.time.multirate;
  setup.max_time_levels = s.time.max_levels;
  if (s.refinement && s.time.multirate.value_or(false) &&  // asked for: refused; default: one step
      s.refinement->settings.max_level + 1 > s.time.max_levels)
    fail({s.time.where.file, s.time.where.line, "time.max_levels"},
         fmt::format("{} time levels, but refinement.max_level {} needs {}", s.time.max_levels,
                     s.refinement->settings.max_level, s.refinement->settings.max_level + 1),
         fmt::format("max_levels >= {} (or time.multirate: false)",
                     s.refinement->settings.max_level + 1));
  return setup;
}

namespace {

/// Every measured notch tip and every probe lies inside the body's bounding box (the particles'
/// cells).
void check_points_inside(const Scene& s, const ParticleStore& p) {
  if (!s.measure && s.output.probes.empty()) return;
  const int dim = s.dimension;
  geometry::Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  for (int a = 0; a < dim; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
    for (std::size_t i = 0; i < p.size(); ++i) {
      lo[a] = std::min(lo[a], p.reference_position[a][i] - 0.5 * p.spacing[i]);
      hi[a] = std::max(hi[a], p.reference_position[a][i] + 0.5 * p.spacing[i]);
    }
  }
  const auto check = [&](const geometry::Vec3& at, const Location& where, const char* what) {
    for (int a = 0; a < dim; ++a)
      if (at[a] < lo[a] || at[a] > hi[a])
        fail(where,
             fmt::format("the {} {} lies outside the body's bounding box", what,
                         point_text(at, dim)),
             fmt::format("{} to {}", point_text(lo, dim), point_text(hi, dim)));
  };
  if (s.measure)
    for (std::size_t k = 0; k < s.measure->settings.tips.size(); ++k)
      check(s.measure->settings.tips[k].at, s.measure->tip_at[k], "notch tip");
  for (const auto& probe : s.output.probes) check(probe.at, probe.where, "probe");
}

/// Whether some other particle lies strictly inside i's horizon (the engine's neighbour search).
bool has_neighbour_within_horizon(const ParticleStore& p, const NeighborSearch& search,
                                  std::size_t i, std::vector<std::int32_t>& found) {
  search.within(i, p.horizon[i], found);
  const auto x = point_of(p.reference_position, i);
  return std::any_of(found.begin(), found.end(), [&](std::int32_t j) {
    const auto d =
        geometry::operator-(point_of(p.reference_position, static_cast<std::size_t>(j)), x);
    return geometry::dot(d, d) < p.horizon[i] * p.horizon[i];
  });
}

/// A particle without a neighbour in its horizon has no stiffness: refused, naming its part. (One
/// whose neighbours all lie across pre-cracks is a free fragment from the start: allowed.)
void check_lonely(const Scene& s, const Simulation& sim, const std::vector<int>& part_of) {
  const auto& p = sim.particles();
  std::unique_ptr<NeighborSearch> search;  // built only when a particle has no bond
  std::vector<std::int32_t> found;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (sim.bonds().own_count(i) > 0) continue;
    if (!search) search = std::make_unique<NeighborSearch>(p.reference_position, p.dim());
    if (has_neighbour_within_horizon(p, *search, i, found)) continue;
    const auto part = part_of[static_cast<std::size_t>(p.id[i])];
    fail(s.body[static_cast<std::size_t>(part)].where,
         fmt::format("the particle at {} has no neighbour inside its horizon {:.6g} m (spacing "
                     "{:.6g} m, horizon factor {})",
                     point_text(point_of(p.reference_position, i), s.dimension), p.horizon[i],
                     p.spacing[i], s.horizon_factor),
         "every particle with at least one neighbour closer than its horizon: a larger "
         "horizon factor, a finer spacing nearby, or remove the isolated point");
  }
}

}  // namespace

std::unique_ptr<Simulation> build_simulation(const Scene& s) {
  auto setup = build_setup(s);
  const auto part_of = setup.points.part;  // the simulation keeps no points
  std::unique_ptr<Simulation> sim;
  try {
    sim = std::make_unique<Simulation>(std::move(setup));
  } catch (const TimeLevelError& e) {
    fail({s.time.where.file, s.time.where.line, "time.max_levels"}, e.what(),
         fmt::format("1 <= max_levels <= {}", kMaxTimeLevels));
  } catch (const MultiHorizonError& e) {
    fail(s.model_where, e.what(),
         "multi-horizon with body parts of different spacing whose coarser particles include "
         "the finer ones near them, or model dual-horizon");
  }
  check_points_inside(s, sim->particles());
  check_lonely(s, *sim, part_of);
  const char* limit = sim->time_levels() ? "stable step of the coarsest particles (time.multirate)"
                                         : "stable time step";
  if (s.time.check_dt && !s.statics && !sim->dt_is_stable())
    fail({s.time.where.file, s.time.where.line, "time.dt"},
         fmt::format("{:.6g} s is above the {} {:.6g} s", sim->dt(), limit, sim->dt_limit()),
         fmt::format("0 < dt <= {:.6g} (time.check_dt: false runs it anyway, to test the guard)",
                     sim->dt_limit()));
  return sim;
}

std::int64_t planned_steps(const Scene& s, double dt) {
  if (s.time.steps) return *s.time.steps;
  return static_cast<std::int64_t>(std::ceil(*s.time.end / dt * (1.0 - 1e-12)));
}

double estimated_memory_bytes(const Simulation& sim) {
  // What the simulation's arrays hold, and a snapshot more: the run keeps the last state that
  // passed the instability guard (runner.cpp, LastGood: the state fields and the rows' flags, and
  // before a refinement event the whole state as a snapshot holds it).
  return static_cast<double>(sim.memory_use().total()) +
         static_cast<double>(simulation_snapshot_bytes(sim));
}

namespace {

/// Shortest text that reads back to the same double.
std::string num(double v) {
  return fmt::format("{}", v);
}

/// At most this many spacings per material are listed; irregular parts (meshes, points files)
/// give every particle its own spacing, and then only the smallest and largest are shown.
constexpr std::size_t kListedSpacings = 16;

/// One particle for each (material, spacing) pair shown in the table.
std::map<std::pair<int, double>, std::size_t> table_rows(const ParticleStore& p) {
  std::map<std::pair<int, double>, std::size_t> first;
  for (std::size_t i = 0; i < p.size(); ++i)
    first.emplace(std::make_pair(p.material[i], p.spacing[i]), i);
  std::map<int, std::size_t> count;
  for (const auto& [key, i] : first) ++count[key.first];
  std::map<std::pair<int, double>, std::size_t> rows;
  for (auto it = first.begin(); it != first.end(); ++it) {
    const int m = it->first.first;
    const bool smallest = it == first.begin() || std::prev(it)->first.first != m;
    const bool largest = std::next(it) == first.end() || std::next(it)->first.first != m;
    if (count[m] <= kListedSpacings || smallest || largest) rows.insert(*it);
  }
  return rows;
}

/// C and s0 for each distinct (material, spacing) pair present in the run (or its extremes).
void emit_material_table(YAML::Emitter& out, const Scene& s, const Simulation& sim) {
  const auto& p = sim.particles();
  out << YAML::Key << "bond_constants" << YAML::Value << YAML::BeginSeq;
  for (const auto& [key, i] : table_rows(p)) {
    const auto& law = s.materials[static_cast<std::size_t>(key.first)].law;
    out << YAML::BeginMap << YAML::Key << "material" << YAML::Value
        << s.materials[static_cast<std::size_t>(key.first)].name;
    out << YAML::Key << "spacing" << YAML::Value << num(key.second);
    out << YAML::Key << "horizon" << YAML::Value << num(p.horizon[i]);
    out << YAML::Key << "micromodulus_C" << YAML::Value << num(sim.micromodulus()[i]);
    if (law.G0 > 0)
      out << YAML::Key << "critical_stretch_s0" << YAML::Value << num(sim.critical_stretch()[i]);
    out << YAML::Key << "rayleigh_speed" << YAML::Value
        << num(rayleigh_speed(law, sim.setup().section));
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

}  // namespace

std::string derived_yaml(const Scene& s, const Simulation& sim) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "derived" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "particles" << YAML::Value << sim.particles().size();
  out << YAML::Key << "bonds" << YAML::Value << sim.bonds().bond_count();
  out << YAML::Key << "row_entries" << YAML::Value << sim.bonds().live;
  out << YAML::Key << "poisson_ratio" << YAML::Value
      << num(implied_poisson_ratio(sim.setup().section));
  emit_material_table(out, s, sim);
  out << YAML::Key << "stable_dt" << YAML::Value << num(sim.critical_dt());
  out << YAML::Key << "dt" << YAML::Value << num(sim.dt());
  out << YAML::Key << "steps" << YAML::Value << planned_steps(s, sim.dt());
  out << YAML::Key << "end_time" << YAML::Value
      << num(static_cast<double>(planned_steps(s, sim.dt())) * sim.dt());
  out << YAML::Key << "estimated_memory_mb" << YAML::Value
      << num(estimated_memory_bytes(sim) / 1e6);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace dhpd::scene
