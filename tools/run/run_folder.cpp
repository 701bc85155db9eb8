// One run per output folder: what counts as a run's outputs, refusing or removing them.
#include "tools/run/run_folder.hpp"

#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "engine/base/errors.hpp"

namespace dhpd::run {

namespace fs = std::filesystem;

namespace {

bool is_run_output(const fs::path& p) {
  static const char* const names[] = {"summary.json",   "history.csv",         "refinement.csv",
                                      "cracks.csv",     "scene.resolved.yaml", "run.log",
                                      "checkpoint.bin", "checkpoint.prev.bin", "report.md",
                                      "plots",          "units.json",          "summary.reserve"};
  const std::string name = p.filename().string();
  for (const char* n : names)
    if (name == n) return true;
  static const std::regex frame(R"(.+_\d{6}\.vtu)"), pvd(R"(.+\.pvd)"), tmp(R"(.+\.tmp.*)");
  return std::regex_match(name, frame) || std::regex_match(name, pvd) ||
         std::regex_match(name, tmp);
}

/// "scene 'plate', status completed, 60 steps" from a summary.json, or what else is known.
std::string describe_run(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in) return "a run without summary.json (killed or still running)";
  try {
    const auto j = nlohmann::json::parse(in);
    return fmt::format("scene '{}', status {}, {} steps", j.value("scene", "?"),
                       j.value("status", "?"), j.value("steps", 0));
  } catch (const std::exception&) {
    return "a run whose summary.json cannot be read";
  }
}

}  // namespace

std::vector<fs::path> run_outputs_in(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (is_run_output(e.path())) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

void claim_folder(const fs::path& dir, bool overwrite, const std::string& action) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(
        fmt::format("output folder {}: it is a file, not a folder (allowed: a "
                    "folder, or a path that does not exist yet)",
                    dir.string()));
  const auto found = run_outputs_in(dir);
  if (found.empty()) return;
  if (!overwrite)
    throw InputError(fmt::format(
        "output folder {} holds the outputs of another run ({}; {} files such as {}): {} would mix "
        "with them. Use --overwrite to remove them first, --restart {} to continue that run, or "
        "another -o folder",
        dir.string(), describe_run(dir), found.size(), found.front().filename().string(), action,
        dir.string()));
  for (const auto& p : found) fs::remove_all(p);
}

}  // namespace dhpd::run
