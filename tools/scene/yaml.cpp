// Reading a scene file: YAML text -> overrides -> checked Scene structs (schema in
// docs/scenes.md).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/base/errors.hpp"
#include "engine/output_fields.hpp"
#include "tools/scene/detail.hpp"

namespace dhpd::scene {

namespace {
std::vector<std::string> field_names(bool always) {
  std::vector<std::string> out;
  for (const auto& f : output_fields())
    if (f.always == always) out.emplace_back(f.name);
  return out;
}
}  // namespace

const std::vector<std::string>& default_fields() {
  static const std::vector<std::string> fields = field_names(true);
  return fields;
}

const std::vector<std::string>& optional_fields() {
  static const std::vector<std::string> fields = field_names(false);
  return fields;
}

namespace {

using detail::Cursor;
using detail::MapView;

const std::vector<std::string> kTopLevelKeys{"name",
                                             "dimension",
                                             "plane",
                                             "thickness",
                                             "area",
                                             "materials",
                                             "body",
                                             "material_regions",
                                             "horizon",
                                             "model",
                                             "partial_volume",
                                             "interfaces",
                                             "cracks",
                                             "no_fail",
                                             "initial_conditions",
                                             "boundary_conditions",
                                             "effects",
                                             "time",
                                             "output",
                                             "measure",
                                             "solver"};

/// The first line whose indentation holds a tab (YAML indents with spaces only), 0 for none.
int tab_indented_line(const std::string& text) {
  int line = 1;
  bool indent = true;
  for (const char ch : text) {
    if (ch == '\n') {
      ++line;
      indent = true;
    } else if (indent && ch == '\t') {
      return line;
    } else if (ch != ' ') {
      indent = false;
    }
  }
  return 0;
}

YAML::Node parse_tree(const std::string& text, const std::string& file) {
  if (const int line = tab_indented_line(text))
    fail(Location{file, line, ""},
         "a tab in the indentation: YAML indents with spaces only (allowed: spaces)");
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    fail(Location{file, e.mark.line + 1, ""}, fmt::format("YAML syntax error: {}", e.msg));
  }
  if (const auto problem = detail::find_tree_problem(root))
    fail(Location{file, problem->line, problem->path}, problem->message);
  if (!root.IsDefined() || root.IsNull()) {
    fail(Location{file, 0, ""},
         "the scene is empty; expected a map with name, dimension, materials, body and time");
  }
  if (!root.IsMap()) {
    fail(Location{file, root.Mark().line + 1, ""},
         fmt::format("the top level of a scene must be a map of keys, got {}",
                     root.IsSequence() ? "a list" : "a single value"));
  }
  return root;
}

/// Reads a key that exists only in one dimension; refuses it in the others.
std::optional<Cursor> dimension_key(const MapView& top, std::string_view key, int only_in,
                                    int dim) {
  auto value = top.get(key);
  if (value && dim != only_in) {
    value->fail(fmt::format("{} applies only to {}D scenes; this scene has dimension {}", key,
                            only_in, dim));
  }
  return value;
}

void read_section(const MapView& top, Scene& s) {
  if (const auto plane = dimension_key(top, "plane", 2, s.dimension)) {
    const std::vector<std::string> words{std::string(to_string(PlaneMode::Stress)),
                                         std::string(to_string(PlaneMode::Strain))};
    s.plane = plane->choice(words) == 0 ? PlaneMode::Stress : PlaneMode::Strain;
  }
  if (const auto h = dimension_key(top, "thickness", 2, s.dimension))
    s.thickness = detail::positive_number(*h);
  if (const auto a = dimension_key(top, "area", 1, s.dimension))
    s.area = detail::positive_number(*a);
}

Section section_of(const Scene& s) {
  return Section{s.dimension, s.plane, s.thickness, s.area};
}

NamedMaterial read_material(const std::string& name, const Cursor& c, const Scene& s) {
  const MapView map(c, {"E", "rho", "G0", "nu"});
  NamedMaterial m{name, {}, c.where()};
  m.law.E = detail::positive_number(map.require("E"));
  m.law.rho = detail::positive_number(map.require("rho"));
  const auto g0 = map.get("G0");
  if (g0) m.law.G0 = detail::non_negative_number(*g0);
  if (s.effects.fracture && !g0)
    c.fail("G0 (fracture energy, J/m^2) is required when effects.fracture is true");
  if (s.effects.fracture && m.law.G0 == 0.0)
    g0->fail("G0 must be > 0 when effects.fracture is true, got 0", "> 0");
  if (const auto nu = map.get("nu")) {
    if (s.family == ModelFamily::Bond) {
      detail::check_poisson(*nu, nu->number(), section_of(s));
    } else {
      m.law.nu = detail::state_poisson_ratio(*nu, s.dimension);
    }
  }
  return m;
}

std::vector<NamedMaterial> read_materials(const Cursor& c, const Scene& s) {
  const MapView map(c, {});
  if (map.entries().empty()) c.fail("define at least one material: name: {E: ..., rho: ...}");
  std::vector<NamedMaterial> materials;
  for (const auto& [name, value] : map.entries())
    materials.push_back(read_material(name, value, s));
  return materials;
}

void read_discretisation(const MapView& top, Scene& s) {
  if (const auto horizon = top.get("horizon"))
    if (const auto factor = MapView(*horizon, {"factor"}).get("factor"))
      s.horizon_factor = detail::horizon_factor(*factor);
  if (const auto pv = top.get("partial_volume")) {
    s.partial_volume = detail::named_choice(
        *pv, std::vector<PartialVolume>{PartialVolume::None, PartialVolume::Linear,
                                        PartialVolume::Exact});
  }
  if (const auto interfaces = top.get("interfaces")) {
    s.interfaces = interfaces->choice({"consistent", "paper"}) == 0;
    if (*s.interfaces && s.family == ModelFamily::Correspondence)
      interfaces->fail(
          "interfaces: consistent corrects the bond-based and ordinary state-based weights; the "
          "correspondence family has no correction",
          "paper (or model family bond or ordinary-state)");
    if (*s.interfaces && s.model != ForceModel::DualHorizon)
      interfaces->fail(fmt::format("interfaces: consistent corrects dual-horizon level jumps; "
                                   "model {} has none to correct",
                                   to_string(s.model)),
                       "paper (or model dual-horizon)");
    for (std::size_t p = 0; p < s.body.size() && *s.interfaces; ++p)
      if (s.body[p].kind != PartKind::Lattice)
        interfaces->fail(fmt::format("interfaces: consistent corrects the level jumps of lattice "
                                     "parts, but body.{} (line {}) is not a lattice",
                                     p, s.body[p].where.line),
                         "paper (or lattice parts only)");
  }
}

TimeSpec read_time(const Cursor& c) {
  const MapView map(c, {"end", "steps", "safety", "dt", "check_dt", "stable_step",
                        "energy_tolerance", "multirate", "max_levels"});
  TimeSpec time;
  time.where = c.where();
  if (map.has("end") == map.has("steps")) {
    c.fail(map.has("end") ? "give either end or steps, not both"
                          : "give the duration as end (s) or as a number of steps",
           "end, steps");
  }
  if (const auto end = map.get("end")) time.end = detail::positive_number(*end);
  if (const auto steps = map.get("steps")) time.steps = detail::positive_integer(*steps);
  if (const auto safety = map.get("safety")) time.safety = detail::safety_factor(*safety);
  if (const auto dt = map.get("dt")) time.dt = detail::positive_number(*dt);
  if (const auto check = map.get("check_dt")) time.check_dt = check->boolean();
  if (const auto step = map.get("stable_step"))
    time.stable_step = step->choice({"lanczos", "bound"}) == 0 ? StableStepEstimate::Lanczos
                                                               : StableStepEstimate::ParticleBound;
  if (const auto tol = map.get("energy_tolerance")) {
    time.energy_tolerance = detail::positive_number(*tol);
    if (time.energy_tolerance > 1.0)
      tol->fail(
          fmt::format("energy_tolerance is a fraction of the energy scale, got {}", tol->text()),
          "0 < energy_tolerance <= 1 (default 0.01)");
  }
  if (const auto multirate = map.get("multirate")) time.multirate = multirate->boolean();
  if (const auto levels = map.get("max_levels")) {
    const auto n = detail::positive_integer(*levels);
    if (n > kMaxTimeLevels)
      levels->fail(fmt::format("{} time levels: the finest step would be dt0 / 2^{}", n, n - 1),
                   fmt::format("1 <= max_levels <= {} (default 8)", kMaxTimeLevels));
    time.max_levels = static_cast<int>(n);
  }
  return time;
}

std::vector<std::string> read_fields(const Cursor& c) {
  std::vector<std::string> fields;
  for (const auto& item : c.list()) {
    const std::string name = item.string();
    const auto& always = default_fields();
    if (std::find(always.begin(), always.end(), name) != always.end())
      item.fail(fmt::format("field '{}' is always written; list only extra fields", name),
                detail::join(optional_fields()));
    item.choice(optional_fields(), "field");
    if (std::find(fields.begin(), fields.end(), name) != fields.end())
      item.fail(fmt::format("field '{}' is listed twice", name));
    fields.push_back(name);
  }
  return fields;
}

/// `output.probes`: named points whose nearest particle history.csv follows.
std::vector<ProbeSpec> read_probes(const Cursor& c, int dim) {
  std::vector<ProbeSpec> probes;
  std::vector<int> name_lines;
  for (const auto& item : c.list()) {
    const MapView map(item, {"name", "at"});
    const Cursor name = map.require("name");
    ProbeSpec probe;
    probe.name = detail::csv_name(name, "probe");
    for (std::size_t k = 0; k < probes.size(); ++k)
      if (probes[k].name == probe.name)
        name.fail(fmt::format("duplicate probe name '{}' (first given on line {})", probe.name,
                              name_lines[k]));
    name_lines.push_back(name.where().line);
    const Cursor at = map.require("at");
    probe.at = at.point(dim);
    probe.where = at.where();
    probes.push_back(std::move(probe));
  }
  return probes;
}

/// `output.sections`: named planes {name, axis, at} whose sectional force history.csv follows.
std::vector<SectionSpec> read_sections(const Cursor& c, int dim) {
  std::vector<SectionSpec> sections;
  for (const auto& item : c.list()) {
    const MapView map(item, {"name", "axis", "at"});
    const Cursor name = map.require("name");
    SectionSpec section;
    section.name = detail::csv_name(name, "section");
    for (const auto& other : sections)
      if (other.name == section.name)
        name.fail(fmt::format("duplicate section name '{}'", section.name));
    section.axis = static_cast<int>(map.require("axis").choice(detail::axis_names(dim)));
    section.at = map.require("at").number();
    sections.push_back(std::move(section));
  }
  return sections;
}

OutputSpec read_output(const Cursor& c, int dim) {
  const MapView map(c,
                    {"directory", "every", "frames", "fields", "history_every", "checkpoint_every",
                     "checkpoint_minutes", "compression", "probes", "sections"});
  OutputSpec out;
  if (const auto dir = map.get("directory")) {
    out.directory = dir->string();
    if (out.directory.empty()) dir->fail("directory must not be empty");
  }
  if (map.has("every") && map.has("frames"))
    c.fail("give either every (steps between frames) or frames (count), not both");
  if (const auto every = map.get("every")) out.every = detail::positive_integer(*every);
  if (const auto frames = map.get("frames")) out.frames = detail::positive_integer(*frames);
  if (!out.every && !out.frames) out.frames = 20;
  if (const auto fields = map.get("fields")) out.fields = read_fields(*fields);
  if (const auto every = map.get("history_every"))
    out.history_every = detail::positive_integer(*every);
  if (const auto every = map.get("checkpoint_every")) {
    out.checkpoint_every = every->integer();
    if (*out.checkpoint_every < 0)
      every->fail(fmt::format("checkpoint_every must be >= 0, got {}", *out.checkpoint_every),
                  ">= 0 (steps between checkpoints; 0: no checkpoint at all)");
  }
  if (const auto minutes = map.get("checkpoint_minutes"))
    out.checkpoint_minutes = detail::non_negative_number(*minutes);
  if (const auto compression = map.get("compression")) {
    static const std::vector<std::string> kCompressions{"lz4", "zlib", "none"};
    out.compression = kCompressions[compression->choice(kCompressions, "compression")];
  }
  if (const auto probes = map.get("probes")) out.probes = read_probes(*probes, dim);
  if (const auto sections = map.get("sections")) out.sections = read_sections(*sections, dim);
  return out;
}

void read_regions_and_loads(const MapView& top, Scene& s) {
  if (const auto cracks = top.get("cracks")) {
    if (s.dimension == 1) cracks->fail("cracks are not available in 1D scenes");
    s.cracks = detail::read_cracks(*cracks, s.dimension);
  }
  if (const auto c = top.get("material_regions"))
    s.material_regions = detail::read_material_regions(*c, s);
  if (const auto c = top.get("no_fail")) s.no_fail = detail::read_regions(*c, s.dimension);
  if (const auto c = top.get("initial_conditions"))
    s.initial_conditions = detail::read_initial_conditions(*c, s.dimension);
  if (const auto c = top.get("boundary_conditions"))
    s.boundary_conditions = detail::read_boundary_conditions(*c, s.dimension);
}

Scene read_scene(const Cursor& root, const std::string& file) {
  const MapView top(root, kTopLevelKeys);
  Scene s;
  s.file = file;
  s.name = detail::scene_name(top.require("name"));
  s.dimension = detail::dimension(top.require("dimension"));
  read_section(top, s);
  const auto effects = top.get("effects");
  std::optional<MapView> effect_map;
  if (effects) effect_map.emplace(*effects, std::vector<std::string>{"fracture", "refinement"});
  if (effect_map)
    if (const auto fracture = effect_map->get("fracture")) s.effects.fracture = fracture->boolean();
  detail::read_model(top, s);
  s.materials = read_materials(top.require("materials"), s);
  s.body = detail::read_body(top.require("body"), s);
  read_discretisation(top, s);
  if (effect_map)
    if (const auto refinement = effect_map->get("refinement"))
      s.refinement = detail::read_refinement(*refinement, s);
  read_regions_and_loads(top, s);
  s.time = read_time(top.require("time"));
  detail::read_solver(top, s);
  detail::check_state_family(top, s);
  detail::check_static_solver(top, s);
  if (const auto output = top.get("output")) {
    s.output = read_output(*output, s.dimension);
  } else {
    s.output.frames = 20;
  }
  // A static run's history has a row per load step unless asked otherwise.
  if (s.statics && !(top.get("output") && MapView(*top.get("output"), {}).has("history_every")))
    s.output.history_every = 1;
  if (const auto measure = top.get("measure")) s.measure = detail::read_measure(*measure, s);
  return s;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& file,
                  const std::vector<Override>& overrides) {
  YAML::Node root = parse_tree(text, file);
  detail::Source source{file, {}};
  source.override_paths = detail::apply_overrides(root, overrides);
  return read_scene(Cursor::root(source, root), file);
}

Scene load_scene(const std::string& file, const std::vector<Override>& overrides) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    fail(Location{file, 0, ""},
         "is a folder, not a scene file (allowed: a YAML scene file, "
         "e.g. cases/branching_plate_uniform.yaml)");
  std::ifstream in(file);
  if (!in) fail(Location{file, 0, ""}, "cannot open the scene file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), file, overrides);
}

}  // namespace dhpd::scene
