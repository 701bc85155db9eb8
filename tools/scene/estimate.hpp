// What a scene will cost before anything is allocated: particles, bonds, memory, time step and
// steps, from closed forms (lattice counts and the lattice neighbours of one interior horizon) —
// so `dhpd check` answers at once and `dhpd run` refuses a scene the machine cannot hold.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "tools/scene/scene.hpp"

namespace dhpd::scene {

struct ResourceEstimate {
  double particles = 0;          ///< at the start (after the static zones are refined)
  bool exact_particles = false;  ///< counted point by point (small lattices, points files)
  double bonds = 0;  ///< own bonds at the start (an interior horizon's count per particle)
  double bytes = 0;  ///< memory of the run (run_bytes)
  /// Refinement's worst case: every particle split down to max_level.
  double particles_worst = 0, bonds_worst = 0, bytes_worst = 0;
  double stable_dt = 0;    ///< of an interior particle of the finest spacing at the start
  double dt = 0;           ///< the step the run takes at the start
  double steps = 0;        ///< planned steps at the start's dt
  double steps_worst = 0;  ///< with the step of the finest level refinement can reach
};

/// The estimate; fast for any scene (no bond is built, no mesh is meshed).
ResourceEstimate estimate_resources(const Scene& s);

/// Bytes a run holds with n particles and b own bonds: its state (engine state_bytes), the
/// guard's copy of what a step changes (the particles' state fields and a flag byte per row
/// entry), the force kernel's packed positions and, while the bonds are searched, the k-d tree; a
/// refining run also copies its whole state (particle fields and flags) before each event.
double run_bytes(double n, double b, ForceModel model, bool refines);

/// The memory a run may use: `max_memory_mb` when given, else the machine's available memory
/// (MemAvailable of /proc/meminfo); +inf when unknown.
double memory_budget_bytes(std::optional<double> max_memory_mb);

/// Refuses (InputError, exit 2) a scene whose estimate does not fit the budget, with the numbers.
void refuse_if_too_big(const Scene& s, const ResourceEstimate& e, double budget_bytes,
                       bool budget_given);

/// The estimate as YAML text (`dhpd check`), with the basis of each number.
std::string estimate_yaml(const ResourceEstimate& e, double budget_bytes);

}  // namespace dhpd::scene
