// history.csv's static columns and relaxation.csv (docs/outputs.md).
#include "tools/output/static_outputs.hpp"

#include <fmt/format.h>

#include "tools/output/text_outputs.hpp"

namespace dhpd::io {
namespace {

constexpr const char* kRelaxationHeader = "load_step,load_factor,iteration,residual,damping";

/// Whether history.csv has condition `bc`'s reaction: every fictitious layer's, and in a static
/// run every fixed or displacement region's.
bool reported(const scene::Scene& s, const BoundaryCondition& bc) {
  if (bc.layer_axis >= 0) return true;
  return s.statics && (bc.kind == BoundaryCondition::Kind::Fixed ||
                       bc.kind == BoundaryCondition::Kind::Displacement);
}

}  // namespace

std::vector<std::string> static_columns(const scene::Scene& s) {
  std::vector<std::string> columns;
  if (s.statics) columns = {"load_factor", "iterations", "relaxations", "residual"};
  const char* axes[] = {"x", "y", "z"};
  for (std::size_t k = 0; k < s.boundary_conditions.size(); ++k)
    if (reported(s, s.boundary_conditions[k].bc))
      for (int a = 0; a < s.dimension; ++a) columns.push_back(fmt::format("bc{}_R{}", k, axes[a]));
  for (const auto& section : s.output.sections)
    for (int a = 0; a < s.dimension; ++a)
      columns.push_back(fmt::format("{}_F{}", section.name, axes[a]));
  return columns;
}

std::vector<double> static_values(const scene::Scene& s, const Simulation& sim) {
  std::vector<double> values;
  if (s.statics) {
    const auto& r = sim.last_relaxation();
    values = {sim.load_factor(), static_cast<double>(r.iterations), static_cast<double>(r.rounds),
              r.residual};
  }
  std::size_t layer = 0;  // layers are numbered in the conditions' order
  for (std::size_t k = 0; k < s.boundary_conditions.size(); ++k) {
    const auto& c = s.boundary_conditions[k];
    if (!reported(s, c.bc)) continue;
    const auto force = c.bc.layer_axis >= 0 ? sim.layer_reaction(layer++)
                                            : reaction_force(sim.loads(), sim.particles(),
                                                             static_cast<std::int32_t>(k));
    for (int a = 0; a < s.dimension; ++a) values.push_back(force[a]);
  }
  for (const auto& section : s.output.sections) {
    const auto force = sim.force_across(section.axis, section.at);
    for (int a = 0; a < s.dimension; ++a) values.push_back(force[a]);
  }
  return values;
}

RelaxationWriter::RelaxationWriter(const std::string& path, bool append)
    : out_(open_csv(path, kRelaxationHeader, "relaxation", append)) {}

void RelaxationWriter::write(const Simulation& sim) {
  std::string rows;
  for (const auto& sample : sim.last_relaxation().trace)
    rows += fmt::format("{},{:.17g},{},{:.17g},{:.17g}\n", sim.steps_done(), sim.load_factor(),
                        sample.iteration, sample.residual, sample.damping);
  write_row(out_, rows, "relaxation");
}

std::uint64_t RelaxationWriter::bytes() {
  return bytes_written(out_);
}

}  // namespace dhpd::io
