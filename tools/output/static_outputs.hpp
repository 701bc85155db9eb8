// What a static run writes beyond a dynamic one (docs/outputs.md): per load step, history.csv's
// load factor, relaxation iterations, residual and each held condition's reaction force; per
// sampled iteration, relaxation.csv.
#pragma once
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "engine/simulation.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::io {

/// history.csv's extra columns: in a static run load_factor, iterations, relaxations, residual;
/// then bcK_Rx, bcK_Ry[, bcK_Rz] (the force on the body) for each fictitious layer K and, in a
/// static run, each fixed or displacement region K (0-based, in the scene's order); then
/// NAME_Fx, ... for each `output.sections` plane (Simulation::force_across).
std::vector<std::string> static_columns(const scene::Scene& s);
/// Their values for the current state.
std::vector<double> static_values(const scene::Scene& s, const Simulation& sim);

/// relaxation.csv: load_step, load_factor, iteration, residual, damping; flushed per load step.
class RelaxationWriter {
 public:
  RelaxationWriter(const std::string& path, bool append);
  /// The trace of the load step the simulation just solved.
  void write(const Simulation& sim);
  std::uint64_t bytes();

 private:
  std::ofstream out_;
};

}  // namespace dhpd::io
