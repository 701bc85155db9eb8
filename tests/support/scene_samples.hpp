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

// Every 2D shape: a plate with a hole and a notch, disk and polygon inclusions, half-space regions.
inline constexpr const char* kShapeScene2D = R"(name: shapes-2d
dimension: 2
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
  steel: {E: 2.0e11, rho: 7850, G0: 1.0e4}
body:
  - shape: difference
    of:
      - {shape: box, min: [0, 0], max: [0.1, 0.04]}
      - {shape: disk, center: [0.05, 0.02], radius: 0.005}
      - {shape: polygon, points: [[0, 0.019], [0.01, 0.02], [0, 0.021]]}
    spacing: 0.001
    material: glass
  - {shape: disk, center: [0.12, 0.02], radius: 0.015, spacing: 0.001, material: glass}
material_regions:
  - region: {shape: disk, center: [0.03, 0.01], radius: 0.004}
    material: steel
  - region:
      shape: union
      of:
        - {shape: polygon, points: [[0.07, 0.025], [0.08, 0.025], [0.075, 0.035]]}
        - {shape: disk, center: [0.12, 0.02], radius: 0.003}
    material: steel
no_fail:
  - {shape: half-space, point: [0.095, 0], normal: [-1, 0]}
initial_conditions:
  - region: {shape: half-space, point: [0.05, 0], normal: [1, 0.5]}
    velocity: [0, 1.0]
boundary_conditions:
  - region: {shape: difference, of: [{shape: box, min: [0, 0], max: [0.1, 0.04]}, {shape: half-space, point: [0, 0.002], normal: [0, 1]}]}
    fixed: true
time: {steps: 10}
)";

// The 3D shapes: a cylinder with a spherical cavity, a tilted cylinder inclusion.
inline constexpr const char* kShapeScene3D = R"(name: shapes-3d
dimension: 3
materials:
  g: {E: 1.0e9, rho: 1000}
  h: {E: 5.0e9, rho: 2000}
body:
  - shape: difference
    of:
      - {shape: cylinder, center: [0, 0, 0], axis: [0, 0, 2], radius: 0.5, height: 1}
      - {shape: sphere, center: [0, 0, 0.5], radius: 0.2}
    spacing: 0.1
    material: g
material_regions:
  - region: {shape: cylinder, center: [0, 0, 0], axis: [1, 1, 1], radius: 0.1, height: 0.4}
    material: h
boundary_conditions:
  - region: {shape: half-space, point: [0, 0, 0.1], normal: [0, 0, 1]}
    fixed: true
time: {steps: 10}
)";

}  // namespace dhpd::scene::samples
