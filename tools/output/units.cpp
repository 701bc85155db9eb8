// The unit sidecar of a run folder (docs/outputs.md).
#include "tools/output/units.hpp"

#include <nlohmann/json.hpp>

#include "engine/output_fields.hpp"

namespace dhpd::io {

std::string units_json() {
  using json = nlohmann::ordered_json;
  json j;
  j["note"] = "SI units; 1 = dimensionless; - = a count, an index or a flag";
  j["history.csv"] = {{"step", "-"},
                      {"time", "s"},
                      {"dt", "s"},
                      {"particles", "-"},
                      {"bonds", "-"},
                      {"broken_bonds", "-"},
                      {"kinetic_energy", "J"},
                      {"strain_energy", "J"},
                      {"external_work", "J"},
                      {"momentum_x", "kg m/s"},
                      {"momentum_y", "kg m/s"},
                      {"momentum_z", "kg m/s"}};
  j["refinement.csv"] = {{"generation", "-"},
                         {"step", "-"},
                         {"time", "s"},
                         {"parents", "-"},
                         {"children", "-"},
                         {"dropped", "-"},
                         {"particles", "-"},
                         {"bonds", "-"},
                         {"rows_rebuilt", "-"},
                         {"bonds_rebuilt", "-"},
                         {"rows_touched", "-"},
                         {"started_broken", "-"},
                         {"started_overstretched", "-"},
                         {"mapping_energy", "J"},
                         {"reduced_fits", "-"},
                         {"dt", "s"},
                         {"seconds", "s (wall)"},
                         {"resorted", "-"},
                         {"resort_seconds", "s (wall)"}};
  j["cracks.csv"] = {{"step", "-"},        {"time", "s"},        {"tip", "name"},
                     {"x", "m"},           {"y", "m"},           {"z", "m"},
                     {"distance", "m"},    {"path_length", "m"}, {"speed", "m/s"},
                     {"angle_deg", "deg"}, {"branches", "-"}};
  j["summary.json"] = {{"wall_seconds", "s (wall)"},
                       {"end_time", "s"},
                       {"dt", "s"},
                       {"critical_dt", "s"},
                       {"bond_updates_per_second", "1/s (wall)"},
                       {"particle_steps_per_second", "1/s (wall)"},
                       {"peak_memory_mb", "MiB (peak resident memory of the process)"},
                       {"allocated_bytes.*", "B (capacities of the simulation's arrays)"},
                       {"bytes_per_particle", "B"},
                       {"bytes_per_directed_bond", "B"},
                       {"rayleigh_speed", "m/s"},
                       {"cracks.*.initiation_time", "s"},
                       {"cracks.*.angle_deg", "deg"},
                       {"cracks.*.initial_angle_deg", "deg"},
                       {"cracks.*.max_speed", "m/s"},
                       {"cracks.*.mean_speed", "m/s"},
                       {"cracks.*.branch_times", "s"},
                       {"cracks.*.branch_speeds", "m/s"},
                       {"cracks.*.branch_positions", "m"},
                       {"cracks.*.tip", "m"},
                       {"seconds_per_phase", "s (wall)"}};
  json frames;
  frames["points"] = "m (reference positions)";
  for (const auto& f : output_fields()) frames[std::string(f.name)] = std::string(f.unit);
  frames["TimeValue"] = "s";
  frames["Step"] = "-";
  j["frames"] = frames;
  return j.dump(2) + "\n";
}

}  // namespace dhpd::io
