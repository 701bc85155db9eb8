// Particles read from a text file: one particle a line, `x y [z] volume [material]`.
#pragma once
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "geometry/lattice.hpp"
#include "geometry/point_size.hpp"

namespace dhpd::scene {

/// How to read a points file.
///
/// Each non-blank line holds `dim` coordinates (m), the particle's volume (m³, > 0) and
/// optionally its material: a name from `materials` or a 0-based index into it. Columns are
/// separated by blanks; `#` starts a comment that runs to the end of the line.
///
/// The file gives true volumes. The point set stores cell measures (length, area or volume, as
/// the lattice does), so the caller passes the section: cell measure = volume / `section`, with
/// `section` = the thickness in 2D, the cross-section area in 1D and 1 in 3D. The spacing Δx of a
/// point is point_size(cell measure, dim, `size_rule`): by default the equivalent diameter of
/// CMAME 2017 §6 (disk or ball of the point's area or volume); `CellSide` gives the lattice
/// spacing cell_measure^(1/dim) back for a lattice written to a file. Its horizon is
/// factor × Δx.
struct PointsFileOptions {
  int dim = 2;
  double section = 1.0;
  geometry::PointSize size_rule = geometry::PointSize::EquivalentDiameter;
  std::vector<std::string> materials;   ///< names, in index order
  std::optional<int> default_material;  ///< for lines without a material column
  int part = 0;                         ///< part index stored with every point
};

/// Reads the file; throws dhpd::InputError "FILE:LINE: message" for a bad number, a wrong
/// number of columns, a volume <= 0, an unknown material and a line without a material when
/// there is no default; "FILE: message" when the file cannot be opened or holds no point.
geometry::PointSet read_points_file(const std::string& path, const PointsFileOptions& options);

/// Same from a stream; `name` stands for the file in messages.
geometry::PointSet parse_points(std::istream& in, const std::string& name,
                                const PointsFileOptions& options);

}  // namespace dhpd::scene
