// A scene file parsed into plain structs (no YAML types here), with the source location of every
// item so later checks can still name file, line and key path.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/discretization/section.hpp"
#include "engine/physics/loads.hpp"
#include "engine/physics/material_law.hpp"
#include "engine/simulation.hpp"
#include "geometry/crack.hpp"
#include "geometry/mesh_points.hpp"
#include "geometry/shapes.hpp"
#include "refine/refiner.hpp"
#include "tools/measure/crack_measure.hpp"

namespace dhpd::scene {

/// Where a value came from: file, 1-based line (0 for command-line overrides), key path.
struct Location {
  std::string file;
  int line = 0;
  std::string path;  ///< e.g. "body.1.spacing"
};

/// Formats "file:line: key.path: message (allowed: ...)" and throws InputError.
[[noreturn]] void fail(const Location& where, std::string_view message,
                       std::string_view allowed = {});

struct NamedMaterial {
  std::string name;
  Material law;
  Location where;
};

/// How a body part makes its particles (docs/scenes.md, `body`).
enum class PartKind {
  Lattice,     ///< a box filled with a cell-centred lattice of `spacing`
  Mesh,        ///< a box triangulated with edges bounded by `mesh` (2D)
  PointsFile,  ///< particles read from `points_file`
};

struct BodyPart {
  PartKind kind = PartKind::Lattice;
  geometry::Shape shape;    ///< Lattice and Mesh (bounded; a Mesh part is a box)
  double spacing = 0.0;     ///< Lattice
  geometry::MeshSize mesh;  ///< Mesh: size, and grading when `graded`
  bool graded = false;      ///< Mesh: `mesh.grading` was given
  std::string points_file;  ///< PointsFile: the path, resolved against the scene's folder
  /// Mesh and PointsFile: Δx of a point from its cell measure (`point_size`, CMAME 2017 §6).
  geometry::PointSize point_size = geometry::PointSize::EquivalentDiameter;
  std::string material;  ///< empty for a PointsFile part whose lines name their material
  Location where;
};

struct Region {
  geometry::Shape shape;
  Location where;
};

/// Particles inside `region` take `material` (inclusions); later entries win.
struct LocatedMaterialRegion {
  geometry::Shape region;
  std::string material;
  Location where;
};

struct LocatedCrack {
  geometry::Crack crack;
  Location where;
};

struct LocatedInitialCondition {
  InitialCondition ic;
  Location where;
};

struct LocatedBoundaryCondition {
  BoundaryCondition bc;
  Location where;
};

/// The most time levels a scene may ask for (time.max_levels).
inline constexpr int kMaxTimeLevels = 16;

struct TimeSpec {
  std::optional<double> end;
  std::optional<std::int64_t> steps;
  double safety = 0.5;
  std::optional<double> dt;
  bool check_dt = true;  ///< refuse a fixed dt above the stable step
  StableStepEstimate stable_step = StableStepEstimate::Lanczos;  ///< how Δt_crit is found
  double energy_tolerance = 0.01;  ///< the instability guard's energy bound (EnergyBudget)
  /// Multi-rate stepping (docs/theory.md §19): true steps each particle at its time level; unset
  /// or false, one global step.
  std::optional<bool> multirate;
  int max_levels = 8;  ///< time levels a run may use
  Location where;      ///< of the `time` map (dt checks refer to time.dt)
};

/// A point whose particle's displacement and velocity history.csv follows (`output.probes`).
struct ProbeSpec {
  std::string name;
  geometry::Vec3 at{0, 0, 0};
  Location where;  ///< of its `at` (checked against the body once it is built)
};

/// A plane whose sectional force history.csv follows (`output.sections`).
struct SectionSpec {
  std::string name;
  int axis = 0;     ///< the plane's normal
  double at = 0.0;  ///< X_axis of the plane
};

struct OutputSpec {
  std::string directory = "out";
  std::optional<std::int64_t> every;   ///< write a frame every N steps, or
  std::optional<std::int64_t> frames;  ///< this many frames spread over the run (default 20)
  std::vector<std::string> fields;     ///< extra point fields beyond the always-written ones
  std::int64_t history_every = 10;
  /// Steps between checkpoints (plus one at the end of the run); 0: none, not even at the end
  /// (SIGINT/SIGTERM still write one); absent: only at the end.
  std::optional<std::int64_t> checkpoint_every;
  /// Also a checkpoint whenever this many minutes of wall time passed since the last one (a
  /// killed run loses at most that much); 0: none by time. Off when checkpoint_every is 0.
  double checkpoint_minutes = 10.0;
  /// How frames are compressed: "lz4" (default), "zlib" or "none" (docs/outputs.md).
  std::string compression = "lz4";
  std::vector<ProbeSpec> probes;      ///< columns NAME_ux ... NAME_vz of history.csv
  std::vector<SectionSpec> sections;  ///< columns NAME_Fx ... of history.csv
};

/// `effects.refinement` (docs/scenes.md): absent or `false` means no refiner at all.
struct RefinementSpec {
  refine::Settings settings;
  Location where;  ///< of the `refinement` key
};

/// `measure` (docs/scenes.md): crack measurements written to cracks.csv and summary.json.
struct MeasureSpec {
  measure::Settings settings;
  std::optional<measure::Published> published;
  std::vector<Location> tip_at;  ///< where each tip's `at` was given (checked against the body)
  Location where;                ///< of the `measure` key
};

/// The point fields every frame carries, and the extra ones `output.fields` may ask for.
const std::vector<std::string>& default_fields();
const std::vector<std::string>& optional_fields();

struct Scene {
  std::string file;
  std::string name;
  int dimension = 2;
  PlaneMode plane = PlaneMode::Stress;
  double thickness = 1.0;  ///< 2D
  double area = 1.0;       ///< 1D
  std::vector<NamedMaterial> materials;
  std::vector<BodyPart> body;
  std::vector<LocatedMaterialRegion> material_regions;
  double horizon_factor = 3.015;
  ForceModel model = ForceModel::DualHorizon;
  ModelFamily family = ModelFamily::Bond;
  Influence influence = Influence::Constant;
  bool surface_correction = true;  ///< state-based family only
  PartialVolume partial_volume = PartialVolume::None;
  /// `interfaces`: consistent (true) or paper (false); absent: consistent_interfaces() decides.
  std::optional<bool> interfaces;
  std::vector<LocatedCrack> cracks;
  std::vector<Region> no_fail;
  std::vector<LocatedInitialCondition> initial_conditions;
  std::vector<LocatedBoundaryCondition> boundary_conditions;
  Effects effects;
  std::optional<RefinementSpec> refinement;
  TimeSpec time;
  OutputSpec output;
  std::optional<MeasureSpec> measure;
  /// `solver: static` (docs/theory.md §22): load steps are time.steps; absent: dynamics.
  std::optional<StaticSolver> statics;
  Location solver_where;  ///< of the `solver` key
  Location model_where;   ///< of the `model` key (empty without one)
};

/// A `--set key.path=value` override; value is parsed as YAML (so `false`, `5e-4`, `[0, 1]` work).
struct Override {
  std::string path;
  std::string value;
};

/// Splits a command-line `key.path=value` at the first '='; throws InputError when there is none.
Override parse_override(std::string_view text);

/// Reads, overrides and validates a scene; throws InputError with file:line: key.path: message.
Scene load_scene(const std::string& file, const std::vector<Override>& overrides = {});
/// Same from text (for tests); `file` only names the source in messages.
Scene parse_scene(const std::string& text, const std::string& file,
                  const std::vector<Override>& overrides = {});

/// Whether level jumps get the interface correction (SimulationSetup::interface_correction): as
/// the scene says, else for dual-horizon scenes whose parts are all lattices.
bool consistent_interfaces(const Scene& scene);

/// The scene with every default filled in, as YAML text (the start of scene.resolved.yaml).
std::string resolved_yaml(const Scene& scene);

}  // namespace dhpd::scene
