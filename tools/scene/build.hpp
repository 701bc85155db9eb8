// From a validated scene to a ready simulation: lattice fill, materials, regions, derived values.
#pragma once
#include <memory>
#include <string>

#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {

/// "[x, y]" of a point's first `dim` coordinates, for messages.
std::string point_text(const geometry::Vec3& x, int dim);

/// Every part's particles in order (lattices filled, meshes meshed, points files read); a point
/// inside a later lattice or mesh part's shape is dropped (that part wins).
geometry::PointSet body_points(const Scene& scene);

/// The setup the engine needs; throws InputError (with file:line) for a region that selects
/// no particle and for parts that produce no particle.
SimulationSetup build_setup(const Scene& scene);

/// The fictitious layer of boundary condition `k` (scene/layers.cpp, docs/theory.md §23): the
/// points of `body` within two horizons of the face, mirrored and appended to `all`; throws
/// InputError at the condition's key where the face is not flat within that width.
FictitiousLayerSpec fictitious_layer(const Scene& s, std::size_t k, const geometry::PointSet& body,
                                     geometry::PointSet& all);

/// Builds the simulation; a fixed `time.dt` above the stable step is refused with its location.
std::unique_ptr<Simulation> build_simulation(const Scene& scene);

/// Number of steps the scene asks for (from time.steps, or ceil(time.end / dt)).
std::int64_t planned_steps(const Scene& scene, double dt);

/// Derived quantities as YAML text (appended to scene.resolved.yaml and printed by `dhpd check`).
std::string derived_yaml(const Scene& scene, const Simulation& sim);

/// Memory of a run's state in bytes: the simulation's arrays and one snapshot (the last good copy
/// the instability guard keeps holds less), without the program itself (about 60 MB).
double estimated_memory_bytes(const Simulation& sim);

}  // namespace dhpd::scene
