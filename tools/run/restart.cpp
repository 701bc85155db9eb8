// Continuing the outputs of a run from its checkpoint (see run_restart.hpp).
#include "tools/run/restart.hpp"

#include <fmt/core.h>

#include "engine/base/errors.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;

bool same_folder(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

/// Copies `from` to `to` through `to.tmp`, keeping only its first `bytes` bytes.
void copy_prefix(const fs::path& from, const fs::path& to, std::uintmax_t bytes) {
  const fs::path tmp = fs::path(to).concat(".tmp");
  fs::copy_file(from, tmp, fs::copy_options::overwrite_existing);
  fs::resize_file(tmp, bytes);
  fs::rename(tmp, to);
}

}  // namespace

void check_restart_outputs(const fs::path& from, const RunState& state,
                           const std::vector<CsvLength>& csvs) {
  std::error_code ec;
  for (const auto& [time, file] : state.frames)
    if (!fs::is_regular_file(from / file, ec))
      throw InputError(fmt::format(
          "--restart {}: frame '{}' (t = {:.6g} s), listed in the checkpoint, is missing",
          from.string(), file, time));
  for (const auto& csv : csvs) {
    const auto size = fs::file_size(from / csv.name, ec);
    if (ec || size < csv.bytes)
      throw InputError(fmt::format(
          "--restart {}: {} is {} than at the checkpoint ({} bytes)", from.string(), csv.name,
          ec ? "missing, not longer" : fmt::format("shorter ({} bytes)", size), csv.bytes));
  }
}

void continue_outputs(const fs::path& from, const fs::path& to, const RunState& state,
                      const std::vector<CsvLength>& csvs) {
  fs::create_directories(to);
  const bool same = same_folder(from, to);
  for (const auto& csv : csvs) {
    if (same)
      fs::resize_file(to / csv.name, csv.bytes);
    else
      copy_prefix(from / csv.name, to / csv.name, csv.bytes);
  }
  if (same) return;
  for (const auto& entry : state.frames) {
    const auto size = fs::file_size(from / entry.second);
    copy_prefix(from / entry.second, to / entry.second, size);
  }
}

}  // namespace dhpd
