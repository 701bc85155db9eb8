// A run folder belongs to one run: a new run refuses a folder that holds another run's outputs
// (exit 2) unless told --overwrite, which removes exactly the files a dhpd run (and dhpd plot /
// report) writes there, and nothing else.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace dhpd::run {

/// The files and folders of dhpd outputs in `dir` (empty when there are none or no folder):
/// summary.json, history.csv, refinement.csv, cracks.csv, scene.resolved.yaml, run.log, units.json,
/// checkpoint.bin, checkpoint.prev.bin, every NAME.pvd and NAME_NNNNNN.vtu, report.md, plots/,
/// and the temporary files of an interrupted atomic write (*.tmp*).
std::vector<std::filesystem::path> run_outputs_in(const std::filesystem::path& dir);

/// Before a new run writes into `dir`: refuses (InputError, exit 2) when it holds another run's
/// outputs and `overwrite` is false, naming that run; with `overwrite`, removes them. `action`
/// says what this run is ("a new run", "the restarted run") for the message.
void claim_folder(const std::filesystem::path& dir, bool overwrite, const std::string& action);

}  // namespace dhpd::run
