// Scenes the statics tests share (tests/tools/test_statics.cpp, test_fictitious_layers.cpp).
#pragma once
#include <string>

namespace dhpd::test {

/// A 0.1 × 0.1 m steel plate (plane stress), its left three columns clamped, σ = 200 MPa on its
/// right column as a body force; `model` and `materials` as given.
inline std::string tension_plate(const std::string& solver, const std::string& model, double nu) {
  return "name: plate\ndimension: 2\nplane: stress\nthickness: 0.01\nmaterials:\n"
         "  steel: {E: 200.0e9, rho: 7850, nu: " +
         std::to_string(nu) +
         "}\nbody:\n  - {shape: box, min: [0, 0], max: [0.1, 0.1], spacing: 0.005, material: "
         "steel}\npartial_volume: linear\nmodel: " +
         model +
         "\nboundary_conditions:\n"
         "  - region: {shape: box, min: [0, 0], max: [0.015, 0.1]}\n    fixed: true\n"
         "  - region: {shape: box, min: [0.095, 0], max: [0.1, 0.1]}\n"
         "    traction: [200.0e6, 0]\n    normal: x\n" +
         solver;
}

/// A 20 mm notched glass plate (5 mm edge notch at mid-height) pulled quasi-statically by 3 µm in
/// ten load steps, its held bands two coarse rows wide with edges between the rows of the 1 mm and
/// 0.5 mm lattices (refined and uniform lattices hold the same material); `spacing`, `effects`
/// and extra `solver` keys (", key: value") as given.
inline std::string notched_plate(double spacing, const std::string& effects,
                                 const std::string& solver_extra = "") {
  return "name: notched\ndimension: 2\nplane: stress\nthickness: 0.001\nmaterials:\n"
         "  glass: {E: 72.0e9, rho: 2440, G0: 3.8}\nbody:\n"
         "  - {shape: box, min: [0, 0], max: [0.02, 0.02], spacing: " +
         std::to_string(spacing) +
         ", material: glass}\n"
         "cracks:\n  - [[0.0, 0.01], [0.005, 0.01]]\npartial_volume: linear\n"
         "boundary_conditions:\n"
         "  - {region: {shape: box, min: [0, 0], max: [0.02, 0.002]}, fixed: true}\n"
         "  - {region: {shape: box, min: [0, 0.018], max: [0.02, 0.02]}, displacement: {y: "
         "3.0e-6}}\n"
         "no_fail:\n  - {shape: box, min: [0, 0], max: [0.02, 0.003]}\n"
         "  - {shape: box, min: [0, 0.017], max: [0.02, 0.02]}\n"
         "effects: " +
         effects + "\nsolver: {type: static, tolerance: 1.0e-5" + solver_extra +
         "}\ntime: {steps: 10}\n";
}

}  // namespace dhpd::test
