// The size Δx of an irregular point (a mesh node, a points-file particle) from its cell measure:
// CMAME 2017 §6, "the material point size Δx is the equivalent diameter ... assuming the material
// point is a circle or sphere". Its horizon is then horizon.factor × Δx.
#pragma once
#include <cmath>
#include <numbers>
#include <string_view>

namespace dhpd::geometry {

/// How Δx follows from a point's cell measure m (length in 1D, area in 2D, volume in 3D).
enum class PointSize {
  /// The diameter of the segment, disk or ball of measure m: m, 2·sqrt(m/π), cbrt(6m/π)
  /// (CMAME 2017 §6). The default for mesh nodes and points files.
  EquivalentDiameter,
  /// The side of the lattice cell of measure m: m^(1/dim) (dhpd before issue 12; what a lattice
  /// written to a points file needs to keep its lattice spacing).
  CellSide,
};

/// Δx of a point of cell measure `measure` (> 0) in dimension `dim` (1 to 3).
inline double point_size(double measure, int dim, PointSize rule) {
  if (rule == PointSize::CellSide)
    return dim == 1 ? measure : (dim == 2 ? std::sqrt(measure) : std::cbrt(measure));
  // The constant outside the root, so a measure near the largest double gives a finite size.
  if (dim == 1) return measure;
  if (dim == 2) return 2.0 / std::sqrt(std::numbers::pi) * std::sqrt(measure);
  return std::cbrt(6.0 / std::numbers::pi) * std::cbrt(measure);
}

/// The scene words for the rules, in enum order.
inline constexpr std::string_view kPointSizeNames[] = {"equivalent-diameter", "cell-side"};

inline std::string_view to_string(PointSize rule) {
  return kPointSizeNames[static_cast<int>(rule)];
}

}  // namespace dhpd::geometry
