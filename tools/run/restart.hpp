// The outputs of a restarted run: the folder of the first run must hold what its checkpoint
// lists (every frame, each CSV at least as long as at the checkpoint); the new folder continues
// them, so its final files are those of a run that never stopped.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tools/run/checkpoints.hpp"

namespace dhpd {

struct CsvLength {
  std::string name;  ///< e.g. "history.csv"
  std::uint64_t bytes = 0;
};

/// Throws InputError (before anything is written) when `from` lacks a frame the checkpoint lists
/// or a CSV is shorter than at the checkpoint.
void check_restart_outputs(const std::filesystem::path& from, const RunState& state,
                           const std::vector<CsvLength>& csvs);

/// Cuts each CSV back to its length at the checkpoint and, when `to` is another folder, copies
/// the CSVs and the listed frames there first (each through a temporary name).
void continue_outputs(const std::filesystem::path& from, const std::filesystem::path& to,
                      const RunState& state, const std::vector<CsvLength>& csvs);

}  // namespace dhpd
