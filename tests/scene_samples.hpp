// Scene texts shared by the scene-reader tests; line numbers in the tests refer to these layouts.
#pragma once

namespace dhpd::scene::samples {

// A 2D scene that uses every feature of the schema.
inline constexpr const char* kFullScene = R"(name: plate-ringing
dimension: 2
plane: strain
thickness: 0.002
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
  steel:
    E: 2.0e11
    rho: 7850
    G0: 1.0e4
    nu: 0.25
body:
  - {shape: box, min: [0, 0], max: [0.1, 0.04], spacing: 0.001, material: glass}
  - {shape: box, min: [0.1, 0], max: [0.12, 0.04], spacing: 0.0005, material: steel}
horizon: {factor: 4}
model: constant-horizon
partial_volume: linear
cracks:
  - [[0.0, 0.02], [0.05, 0.02]]
no_fail:
  - {shape: box, min: [0.09, 0], max: [0.12, 0.04]}
initial_conditions:
  - region: {shape: box, min: [0, 0], max: [0.1, 0.04]}
    velocity: [1.0, 0]
    strain: [1e-4, 0]
    gaussian: {center: [0.05, 0.02], width: 0.01}
boundary_conditions:
  - region: {shape: box, min: [0, 0], max: [0.003, 0.04]}
    fixed: true
  - region: {shape: box, min: [0.117, 0], max: [0.12, 0.04]}
    velocity: {x: 0.1}
  - region: {shape: box, min: [0, 0.037], max: [0.12, 0.04]}
    traction: [0, 1.0e6]
    normal: y
effects: {fracture: true}
time:
  end: 1.0e-5
  safety: 0.5
  dt: 1.0e-8
output:
  directory: results
  every: 100
  fields: [strain_energy_density, bond_count]
  history_every: 5
)";

// Seven numbered lines that the bad-scene table edits.
inline constexpr const char* kMinimal = R"(name: t
dimension: 2
materials:
  glass: {E: 1.0e9, rho: 1000, G0: 1.0}
body:
  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, material: glass}
time: {end: 1.0}
)";

}  // namespace dhpd::scene::samples
