// What one refinement event carries between its phases (simulation_refine.cpp and
// simulation_rows.cpp only).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/particles.hpp"
#include "engine/refinement_event.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

struct Simulation::EventScratch {
  SplitPlan plan;
  ParticleStore parents;               ///< the parents' fields before the split
  std::vector<std::int32_t> near;      ///< previous-generation owners near the parents (rule b)
  std::vector<std::int32_t> owners;    ///< bond rows rebuilt, ascending
  std::vector<std::int32_t> dirty;     ///< interaction rows rewritten, ascending
  std::vector<std::int32_t> children;  ///< child slots, ascending
};

}  // namespace dhpd
