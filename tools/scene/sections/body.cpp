// The `body` section: lattice parts (`spacing`), meshed parts (`mesh`) and points files.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kShapePartExtraKeys{"spacing", "mesh", "point_size", "material"};
const std::vector<std::string> kFilePartKeys{"points_file", "point_size", "material"};

/// `point_size: equivalent-diameter | cell-side` of a mesh or points-file part.
void read_point_size(const MapView& map, BodyPart& part) {
  const auto given = map.get("point_size");
  if (!given) return;
  if (part.kind == PartKind::Lattice)
    given->fail(
        "point_size applies to mesh and points-file parts; a lattice part's particle size is its "
        "spacing",
        "mesh or points_file parts only");
  const std::vector<std::string> names(std::begin(geometry::kPointSizeNames),
                                       std::end(geometry::kPointSizeNames));
  part.point_size = static_cast<geometry::PointSize>(given->choice(names));
}

/// `mesh: {size: S, grading: {from: point, rate: r}}`; the size is checked against the box.
void read_mesh(const Cursor& c, BodyPart& part, int dim) {
  if (dim == 1) c.fail("mesh parts are available in 2D and 3D only; this scene is 1D");
  const MapView map(c, {"size", "grading"});
  const Cursor size = map.require("size");
  part.mesh.size = positive_number(size);
  check_spacing(size, part.mesh.size, part.shape.bounds(dim), dim);
  if (const auto grading = map.get("grading")) {
    const MapView g(*grading, {"from", "rate"});
    part.mesh.from = g.require("from").point(dim);
    part.mesh.rate = non_negative_number(g.require("rate"));
    part.graded = true;
  }
}

/// A lattice part (`spacing`) of any bounded shape, or a meshed part (`mesh`) of a box.
BodyPart read_shape_part(const Cursor& c, const Scene& s) {
  auto [shape, map] = shape_from(c, s.dimension, kShapePartExtraKeys);
  BodyPart part;
  part.where = c.where();
  part.shape = std::move(shape);
  const geometry::Box bounds = part.shape.bounds(s.dimension);
  if (!bounds.finite(s.dimension))
    map.require("shape").fail(
        "a body part must be bounded, but this shape reaches infinity (a half-space alone, or a "
        "union holding one); cut it with a bounded shape, e.g. {shape: difference, of: [{shape: "
        "box, ...}, {shape: half-space, ...}]}");
  if (map.has("spacing") == map.has("mesh")) {
    c.fail(map.has("spacing")
               ? "give either spacing (a lattice) or mesh (a triangulation), not both"
               : "give the particle spacing, or mesh: {size: ...} for a mesh",
           "spacing, mesh");
  }
  if (const auto spacing = map.get("spacing")) {
    part.spacing = positive_number(*spacing);
    check_spacing(*spacing, part.spacing, bounds, s.dimension);
  } else {
    if (part.shape.node(part.shape.root()).kind != geometry::Shape::Kind::Box)
      map.require("shape").fail("a meshed part must be a box for now", "box");
    part.kind = PartKind::Mesh;
    read_mesh(*map.get("mesh"), part, s.dimension);
  }
  read_point_size(map, part);
  part.material = material_name(map.require("material"), s);
  return part;
}

/// `{points_file: PATH, material: NAME}`: PATH relative to the scene file's folder.
BodyPart read_file_part(const Cursor& c, const Scene& s) {
  const MapView map(c, kFilePartKeys);
  BodyPart part;
  part.kind = PartKind::PointsFile;
  part.where = c.where();
  const Cursor file = map.require("points_file");
  const fs::path given = file.string();
  if (given.empty()) file.fail("points_file must not be empty");
  const fs::path folder = fs::path(s.file).parent_path();
  part.points_file =
      fs::absolute(given.is_absolute() ? given : folder / given).lexically_normal().string();
  if (!fs::is_regular_file(part.points_file))
    file.fail(fmt::format("points file '{}' does not exist (looked for {})", given.string(),
                          part.points_file));
  read_point_size(map, part);
  if (const auto material = map.get("material")) part.material = material_name(*material, s);
  return part;
}

}  // namespace

std::vector<BodyPart> read_body(const Cursor& c, const Scene& s) {
  std::vector<BodyPart> body;
  for (const auto& item : c.list()) {
    const bool from_file = item.node().IsMap() && item.node()["points_file"];
    body.push_back(from_file ? read_file_part(item, s) : read_shape_part(item, s));
  }
  if (body.empty()) c.fail("the body needs at least one part, e.g. - {shape: box, ...}");
  return body;
}

}  // namespace dhpd::scene::detail
