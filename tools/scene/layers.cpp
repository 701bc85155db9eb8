// The particles of fictitious boundary layers (docs/theory.md §23) for the scene builder: the
// body's points near a flat face, mirrored, and the layer's rule; refused where the face is not
// flat.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "geometry/mirror_layer.hpp"
#include "tools/scene/build.hpp"

namespace dhpd::scene {

/// The layer of boundary condition `k` (a `fictitious_layer`): the body's points `pts` within one
/// horizon of the face, mirrored (docs/theory.md §23), appended to `all`. Refused
/// where the face is not flat within that width.
FictitiousLayerSpec fictitious_layer(const Scene& s, std::size_t k, const geometry::PointSet& pts,
                                     geometry::PointSet& all) {
  const auto& bc = s.boundary_conditions[k];
  const int axis = bc.bc.layer_axis, side = bc.bc.layer_side;
  const Location layer_at{bc.where.file, bc.where.line, bc.where.path + ".fictitious_layer"};
  if (s.refinement)
    fail(layer_at,
         "refinement with fictitious layers is not available yet (an event renumbers "
         "the particles a layer mirrors)",
         "region conditions with effects.refinement, or no refinement");
  if (s.time.multirate.value_or(false))
    fail(layer_at,
         "time levels with fictitious layers are not available (a layer follows the "
         "body once per step)",
         "time.multirate: false or unset");
  const double face = geometry::face_coordinate(pts, axis, side);
  double spacing = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    largest = std::max(largest, pts.spacing[i]);
    if (std::abs(face - pts.position[i][axis]) <= 0.5 * pts.spacing[i] * (1 + 1e-9))
      spacing = std::max(spacing, pts.spacing[i]);
  }
  const double width =
      2.0 * s.horizon_factor * (s.model == ForceModel::ConstantHorizon ? largest : spacing);
  FictitiousLayerSpec spec;
  spec.axis = axis;
  spec.side = side;
  spec.condition = k;
  const auto layer = geometry::mirror_layer(pts, axis, side, width, spec.mirrors);
  const Location where{bc.where.file, bc.where.line, bc.where.path + ".fictitious_layer"};
  // Flat: each mirrored particle's part is a lattice whose shape holds the face's point on the
  // particle's line (a disk's or a stepped body's points near the plane do not reach it).
  for (const auto m : spec.mirrors) {
    const auto part_index = static_cast<std::size_t>(pts.part[static_cast<std::size_t>(m)]);
    const auto& part = s.body[part_index];
    auto at_face = pts.position[static_cast<std::size_t>(m)];
    at_face[axis] = face - side * 1e-9 * std::max(1.0, std::abs(face));
    if (part.kind != PartKind::Lattice || !part.shape.contains(at_face, s.dimension))
      fail(where,
           fmt::format("the body's face at {} = {:.6g} is not flat within two horizons ({:.6g} "
                       "m): part {} {} at {}",
                       "xyz"[axis], face, width, part_index + 1,
                       part.kind != PartKind::Lattice ? "is not a lattice, its particle"
                                                      : "does not reach the face from its particle",
                       point_text(pts.position[static_cast<std::size_t>(m)], s.dimension)),
           "a face of the body's bounding box that lattice parts reach straight (a curved or "
           "stepped boundary cannot be mirrored: use region conditions there)");
  }
  const auto first = static_cast<std::int32_t>(all.size());
  for (std::size_t i = 0; i < layer.size(); ++i) {
    all.position.push_back(layer.position[i]);
    all.cell_measure.push_back(layer.cell_measure[i]);
    all.spacing.push_back(layer.spacing[i]);
    all.material.push_back(layer.material[i]);
    all.part.push_back(layer.part[i]);
    spec.points.push_back(first + static_cast<std::int32_t>(i));
  }
  if (bc.bc.kind == BoundaryCondition::Kind::Traction) {
    spec.rule = FictitiousLayerSpec::Rule::Traction;
    spec.traction = bc.bc.traction;
  } else {
    spec.displacement = bc.bc.displacement;
    if (bc.bc.kind == BoundaryCondition::Kind::Fixed)
      for (int a = 0; a < s.dimension; ++a) spec.displacement[a] = 0.0;
  }
  return spec;
}

}  // namespace dhpd::scene
