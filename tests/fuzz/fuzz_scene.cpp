// libFuzzer target for the scene loader: YAML text (+ optional --set overrides) -> Scene ->
// validation -> resolved scene read back -> setup and simulation for small scenes.
//
// Input: a scene file; everything after a line `#%set` is read as one `key.path=value` override
// per line (so the input stays a valid scene when the marker is absent).
//
// Contract checked (a violation aborts, which libFuzzer reports as a crash):
// - bad input only ever throws dhpd::InputError, with a non-empty message;
// - an accepted scene's resolved YAML reads back to the same resolved YAML;
// - small accepted scenes build (or are refused with InputError) and their derived values print.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace {

using dhpd::scene::Scene;

/// Scenes planned above these sizes stop after validation: a fuzz input must not be able to ask
/// for a billion particles or bonds.
constexpr double kMaxLatticeParticles = 2000;
constexpr double kMaxMeshNodes2d = 300;
constexpr double kMaxNeighbourWork = 2e5;  ///< particles × horizon factor^dim

[[noreturn]] void contract_broken(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_scene: %s: %s\n", what, detail.c_str());
  std::abort();
}

struct Input {
  std::string scene;
  std::vector<std::string> overrides;
};

Input split_input(const std::string& data) {
  const std::string marker = "#%set\n";
  const auto at = data.find(marker);
  if (at == std::string::npos) return {data, {}};
  Input input{data.substr(0, at), {}};
  std::istringstream rest(data.substr(at + marker.size()));
  for (std::string line; std::getline(rest, line);) input.overrides.push_back(line);
  return input;
}

/// Upper estimate of the particles a scene creates; infinity when it cannot be bounded cheaply
/// (points files: any file on the machine; 3D meshes: Mesh_3 is slow even when small).
double planned_particles(const Scene& s) {
  double total = 0.0;
  for (const auto& part : s.body) {
    if (part.kind == dhpd::scene::PartKind::PointsFile) return INFINITY;
    if (part.kind == dhpd::scene::PartKind::Mesh && s.dimension == 3) return INFINITY;
    const auto box = part.shape.bounds(s.dimension);
    const double h = part.kind == dhpd::scene::PartKind::Lattice ? part.spacing : part.mesh.size;
    double cells = 1.0;
    for (int a = 0; a < s.dimension; ++a) cells *= (box.max[a] - box.min[a]) / h + 2.0;
    if (part.kind == dhpd::scene::PartKind::Mesh) {
      cells *= 3.0;  // about 2.3 nodes per size² cell for well-shaped triangles
      if (cells > kMaxMeshNodes2d) return INFINITY;
    }
    total += cells;
  }
  return total;
}

void check_resolved_round_trip(const Scene& scene) {
  const std::string resolved = dhpd::scene::resolved_yaml(scene);
  Scene again;
  try {
    again = dhpd::scene::parse_scene(resolved, scene.file);
  } catch (const dhpd::InputError& e) {
    contract_broken("the resolved scene is refused", std::string(e.what()) + "\n" + resolved);
  }
  if (dhpd::scene::resolved_yaml(again) != resolved)
    contract_broken("the resolved scene does not read back to itself", resolved);
}

void build_small(const Scene& scene) {
  const double particles = planned_particles(scene);
  if (!(particles <= kMaxLatticeParticles)) return;
  if (particles * std::pow(scene.horizon_factor + 1.0, scene.dimension) > kMaxNeighbourWork) return;
  const auto sim = dhpd::scene::build_simulation(scene);
  const std::string derived = dhpd::scene::derived_yaml(scene, *sim);
  if (derived.empty()) contract_broken("no derived values", scene.name);
}

void run_one(const Input& input) {
  std::vector<dhpd::scene::Override> overrides;
  for (const auto& line : input.overrides) overrides.push_back(dhpd::scene::parse_override(line));
  const Scene scene = dhpd::scene::parse_scene(input.scene, "/fuzz/scene.yaml", overrides);
  check_resolved_round_trip(scene);
  build_small(scene);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Input input = split_input(std::string(reinterpret_cast<const char*>(data), size));
  try {
    run_one(input);
  } catch (const dhpd::InputError& e) {
    if (std::string(e.what()).empty()) contract_broken("InputError without a message", "");
  } catch (const std::exception& e) {
    contract_broken("not an InputError", e.what());
  }
  return 0;
}
