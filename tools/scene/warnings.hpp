// What is legal in a scene but probably not meant: a pre-crack that cuts no bond, a no-fail or
// material region that holds no particle, a run of more steps than anyone waits for. Warnings,
// not errors: the run goes on, the log and summary.json say it (and `dhpd check` prints them).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/simulation.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {

/// More steps than this are warned about (a 2D plate of 16,000 particles does about 2,000 steps
/// a second here: 10 million steps are over an hour of a small run).
inline constexpr std::int64_t kManySteps = 10'000'000;

/// The warnings of a scene against its built simulation, each "file:line: key.path: message".
std::vector<std::string> scene_warnings(const Scene& s, const Simulation& sim,
                                        std::int64_t planned_steps);

}  // namespace dhpd::scene
