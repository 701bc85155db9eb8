// Private helpers of the scene reader: a YAML node with its key path and source location, a map
// view that refuses duplicate and unknown keys, and the value checks. Not part of the public API.
#pragma once
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tools/scene/scene.hpp"

namespace dhpd::scene::detail {

/// Name of the pseudo-file that locations of command-line overrides carry.
inline constexpr std::string_view kOverrideSource = "--set";

/// Where the tree came from: the scene file and the key paths replaced from the command line.
struct Source {
  std::string file;
  std::vector<std::string> override_paths;
};

/// A YAML node with its key path and the line it was written on (key line for map values).
class Cursor {
 public:
  Cursor(const Source& source, YAML::Node node, std::string path, int line, bool overridden);
  static Cursor root(const Source& source, const YAML::Node& node);

  const YAML::Node& node() const { return node_; }
  const std::string& path() const { return path_; }
  std::string_view key() const;  ///< last path component
  Location where() const;
  [[noreturn]] void fail(std::string_view message, std::string_view allowed = {}) const;

  Cursor child(std::string key, const YAML::Node& value, const YAML::Node& key_node) const;
  Cursor element(std::size_t index, const YAML::Node& value) const;

  std::string describe() const;  ///< "'text'", "a list", "a map" or "nothing", for messages
  std::string text() const;      ///< the scalar as written, or describe() for other nodes
  double number() const;
  std::int64_t integer() const;
  bool boolean() const;
  std::string string() const;
  std::vector<Cursor> list() const;
  std::vector<Cursor> list_of_size(std::size_t size, std::string_view what) const;
  /// A list of exactly `dim` numbers; unused axes stay 0.
  geometry::Vec3 point(int dim) const;
  /// Index of the word in `allowed`; unknown words fail with a suggestion and the allowed list.
  /// `what` names the word in the message (default: the key).
  std::size_t choice(const std::vector<std::string>& allowed, std::string_view what = {}) const;

 private:
  const Source* source_;
  YAML::Node node_;
  std::string path_;
  int line_;
  bool overridden_;
};

/// The entries of a YAML map, refusing duplicate keys and (when `allowed` is not empty) unknown
/// keys with a "did you mean" suggestion.
class MapView {
 public:
  MapView(const Cursor& map, const std::vector<std::string>& allowed);

  const Cursor& self() const { return self_; }
  bool has(std::string_view key) const { return get(key).has_value(); }
  std::optional<Cursor> get(std::string_view key) const;
  Cursor require(std::string_view key) const;
  const std::vector<std::pair<std::string, Cursor>>& entries() const { return entries_; }

 private:
  Cursor self_;
  std::vector<std::pair<std::string, Cursor>> entries_;
};

/// The value of `values` whose to_string is the word at `c` (Cursor::choice's message otherwise).
template <class E>
E named_choice(const Cursor& c, const std::vector<E>& values) {
  std::vector<std::string> words;
  for (const auto v : values) words.emplace_back(to_string(v));
  return values[c.choice(words)];
}

/// Comma-separated list of words, for "(allowed: ...)".
std::string join(const std::vector<std::string>& words);
/// The closest word of `candidates` within a small edit distance, if any.
std::optional<std::string> closest_word(std::string_view word,
                                        const std::vector<std::string>& candidates);
/// Axis names "x", "y", "z" limited to the dimension.
std::vector<std::string> axis_names(int dim);

/// Limits on the shape of a YAML tree (scene_tree.cpp): nesting depth, and values repeated by
/// expanding aliases (an anchored value used again counts once per use).
inline constexpr std::size_t kMaxSceneDepth = 64;
inline constexpr std::size_t kMaxAliasExpansion = 10000;

/// Why a tree cannot be read, with the 1-based line of the offending value (0 when unknown).
struct TreeProblem {
  int line = 0;
  std::string path;  ///< key path of the offending value
  std::string message;
};
/// A cycle (an alias inside the value it names), nesting beyond kMaxSceneDepth, or aliases
/// expanding beyond kMaxAliasExpansion repeated values; nothing for an ordinary tree.
std::optional<TreeProblem> find_tree_problem(const YAML::Node& root);

/// Replaces the nodes named by the overrides (see docs/scenes.md, "Command-line overrides");
/// returns their key paths with list indices written canonically.
std::vector<std::string> apply_overrides(YAML::Node& root, const std::vector<Override>& overrides);

// Value checks (scene_validate.cpp); each reads the cursor's value and fails with its location.
double positive_number(const Cursor& c);
/// ν of a state-based material: in (−1, 0.5); refused in 1D (docs/scenes.md, materials).
double state_poisson_ratio(const Cursor& c, int dim);
double non_negative_number(const Cursor& c);
std::int64_t positive_integer(const Cursor& c);
double horizon_factor(const Cursor& c);
double safety_factor(const Cursor& c);
int dimension(const Cursor& c);
std::string scene_name(const Cursor& c);
/// Fails unless max > min on every axis of the dimension.
void check_box(const Cursor& at, const geometry::Box& box, int dim);
/// Fails unless 0 < spacing <= the smallest extent of the box (also used for a mesh size; the
/// message names the cursor's key).
void check_spacing(const Cursor& at, double spacing, const geometry::Box& box, int dim);
/// Fails when a given Poisson's ratio differs from the one bond-based PD implies.
void check_poisson(const Cursor& at, double nu, const Section& section);
/// 2D: two distinct points; 3D: four coplanar corners.
void check_crack(const Cursor& at, const geometry::Crack& crack, int dim);

// Shapes (scene_shapes.cpp).
/// The shape of a map `{shape: WORD, ...}` that may also hold the `extra` keys the caller reads
/// from the returned map view (unknown keys are refused with a suggestion).
std::pair<geometry::Shape, MapView> shape_from(const Cursor& c, int dim,
                                               const std::vector<std::string>& extra);
/// A list of `dim` numbers that is not the zero vector (the message names the key).
geometry::Vec3 nonzero_vector(const Cursor& c, int dim);
/// `{shape: random-disks, ...}` (scene_random_disks.cpp): the union of the disks it places.
geometry::Shape read_random_disks(const MapView& map);
/// A region: a map of exactly one shape's keys.
geometry::Shape read_shape(const Cursor& c, int dim);
/// The scene word of node `index` of a shape ("disk" in 2D, "sphere" in 3D for a ball).
std::string shape_word(const geometry::Shape& shape, int index, int dim);

// Section readers (scene_regions.cpp), shared by the top-level reader.
std::vector<LocatedCrack> read_cracks(const Cursor& c, int dim);
std::vector<Region> read_regions(const Cursor& c, int dim);
std::vector<LocatedMaterialRegion> read_material_regions(const Cursor& c, const Scene& s);
/// Fails unless the material named at `c` is defined in the scene (with a suggestion).
std::string material_name(const Cursor& c, const Scene& s);
std::vector<LocatedInitialCondition> read_initial_conditions(const Cursor& c, int dim);
std::vector<LocatedBoundaryCondition> read_boundary_conditions(const Cursor& c, int dim);

/// `model` (sections/model.cpp): its word or map into the scene's family, horizon rule, influence
/// and surface correction.
void read_model(const MapView& top, Scene& s);
/// What the state-based family refuses (time.stable_step: bound, time.multirate: true); model
/// and time must already be read.
void check_state_family(const MapView& top, const Scene& s);

/// `solver` (sections/solver.cpp): dynamic, static or {type, tolerance, ...}; and what a static
/// run refuses (time.end, time.dt, levels, refinement, velocity conditions, classical variable).
void read_solver(const MapView& top, Scene& s);

/// A held component over time (sections/time_function.cpp): {ramp: T, to: V} or {table: [[t, v],
/// ...] | FILE.csv} (a file relative to `scene_file`'s folder); times strictly increasing.
TimeFunction read_time_function(const Cursor& c, const std::string& scene_file);
void check_static_solver(const MapView& top, const Scene& s);

/// `effects.refinement` (scene_refinement.cpp); body and model must already be read.
std::optional<RefinementSpec> read_refinement(const Cursor& c, const Scene& s);

/// The `measure` block (scene_measure.cpp); effects must already be read.
MeasureSpec read_measure(const Cursor& c, const Scene& s);
/// A name that is written as a CSV cell or column (a tip, a probe): letters, digits, '_', '.', '-'.
std::string csv_name(const Cursor& c, std::string_view what);

/// The `body` list (scene_body.cpp); materials must already be read.
std::vector<BodyPart> read_body(const Cursor& c, const Scene& s);

}  // namespace dhpd::scene::detail
