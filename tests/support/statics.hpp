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

}  // namespace dhpd::test
