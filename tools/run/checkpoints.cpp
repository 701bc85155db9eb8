// Run checkpoints: the simulation's snapshot and the run loop's state in one checkpoint file.
#include "tools/run/checkpoints.hpp"

#include <fmt/core.h>

#include <filesystem>
#include <sstream>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/archive.hpp"
#include "engine/checkpoint/checkpoint.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;

template <class State, class Ar>
void run_fields(State& s, Ar& ar) {
  ar(s.planned_steps), ar(s.schedule_position), ar(s.frames);
  ar(s.history_bytes), ar(s.refinement_bytes), ar(s.cracks_bytes), ar(s.relaxation_bytes);
  ar(s.refinement_events), ar(s.particles_start), ar(s.wall_seconds), ar(s.rayleigh_speed);
  ar(s.derived_text);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The key path of line `at` of emitted YAML: the keys of the less indented lines above it.
std::string key_path(const std::vector<std::string>& lines, std::size_t at) {
  std::vector<std::pair<std::size_t, std::string>> stack;  // (indent, key)
  for (std::size_t k = 0; k <= at && k < lines.size(); ++k) {
    const auto& line = lines[k];
    std::size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos) continue;
    std::string rest = line.substr(indent);
    if (rest.rfind("- ", 0) == 0) rest = rest.substr(2), indent += 2;
    const auto colon = rest.find(':');
    const std::string key = colon == std::string::npos || rest[0] == '{' || rest[0] == '['
                                ? std::string("-")
                                : rest.substr(0, colon);
    while (!stack.empty() && stack.back().first >= indent) stack.pop_back();
    stack.emplace_back(indent, key);
  }
  std::string path;
  for (const auto& [indent, key] : stack) path += (path.empty() ? "" : ".") + key;
  return path;
}

}  // namespace

std::string checkpoint_scene_text(const scene::Scene& scene) {
  auto s = scene;
  s.output.directory.clear();
  s.output.checkpoint_every.reset();
  s.output.checkpoint_minutes = 0.0;  // when to checkpoint changes no number of the run
  s.output.compression = "lz4";       // nor how frames are compressed
  return scene::resolved_yaml(s);
}

std::string checkpoint_path(const std::string& where) {
  std::error_code ec;
  if (fs::is_regular_file(where, ec)) return where;
  return (fs::path(where) / "checkpoint.bin").string();
}

std::string first_difference(const std::string& checkpoint_text, const std::string& run_text) {
  const auto a = lines_of(checkpoint_text), b = lines_of(run_text);
  std::size_t k = 0;
  while (k < a.size() && k < b.size() && a[k] == b[k]) ++k;
  const auto show = [](const std::vector<std::string>& lines, std::size_t at) {
    if (at >= lines.size()) return std::string("nothing more");
    const auto begin = lines[at].find_first_not_of(' ');
    return fmt::format("`{}`", lines[at].substr(begin == std::string::npos ? 0 : begin));
  };
  const auto& longer = k < b.size() ? b : a;
  return fmt::format("at {} the checkpoint has {}, this run has {}", key_path(longer, k),
                     show(a, k), show(b, k));
}

StagedCheckpoint::StagedCheckpoint(std::string path, std::unique_ptr<AtomicFile> file)
    : path_(std::move(path)), file_(std::move(file)) {}
StagedCheckpoint::StagedCheckpoint(StagedCheckpoint&&) noexcept = default;
StagedCheckpoint::~StagedCheckpoint() = default;

std::size_t StagedCheckpoint::commit() {
  file_->commit((fs::path(path_).parent_path() / "checkpoint.prev.bin").string());
  file_.reset();
  std::error_code ec;
  return static_cast<std::size_t>(fs::file_size(path_, ec));
}

StagedCheckpoint stage_checkpoint(const std::string& path, const Simulation& sim,
                                  const RunState& state, const std::string& scene_text) {
  archive::Writer run;
  run_fields(state, run);
  run(static_cast<std::uint8_t>(state.cracks != nullptr));
  if (state.cracks) measure::CrackTracker::archive_state(std::as_const(*state.cracks), run);
  return {path, stage_checkpoint_file(path, scene_text, sim, run.bytes())};
}

std::size_t write_checkpoint(const std::string& path, const Simulation& sim, const RunState& state,
                             const std::string& scene_text) {
  return stage_checkpoint(path, sim, state, scene_text).commit();
}

void load_checkpoint(const std::string& path, Simulation& sim, RunState& state,
                     const std::string& scene_text) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(
        fmt::format("--restart: no checkpoint '{}' (a run writes one at its end, "
                    "and every output.checkpoint_every steps)",
                    path));
  const MappedFile file(path);
  const auto parts = decode_checkpoint(file.bytes(), path);
  if (parts.scene_text != scene_text)
    throw InputError(fmt::format(
        "{}: the checkpoint was written for another scene or other --set overrides: {} (restart "
        "with the scene and overrides of the first run)",
        path, first_difference(parts.scene_text, scene_text)));
  if (parts.fingerprint != sim.fingerprint())
    throw InputError(fmt::format(
        "{}: the scene's particles differ from the checkpoint's (a points file or mesh changed "
        "since the first run)",
        path));
  archive::Reader run(parts.run_state, path);
  run_fields(state, run);
  std::uint8_t has_cracks = 0;
  run(has_cracks);
  if ((has_cracks != 0) != (state.cracks != nullptr) ||
      (state.cracks && !measure::CrackTracker::archive_state(*state.cracks, run)) ||
      run.remaining() != 0)
    run.fail("its crack measurements do not fit the scene's measure block");
  load_simulation(parts.simulation, sim, path);
}

}  // namespace dhpd
