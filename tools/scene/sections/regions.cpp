// Scene sections made of regions: cracks, no-fail zones, material regions, initial and boundary
// conditions.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

/// The centre of the region's bounds, or 0 on the axes where the region is unbounded.
geometry::Vec3 region_centre(const geometry::Shape& region, int dim) {
  const geometry::Box box = region.bounds(dim);
  geometry::Vec3 centre{0, 0, 0};
  for (int a = 0; a < dim; ++a)
    if (std::isfinite(box.min[a]) && std::isfinite(box.max[a]))
      centre[a] = 0.5 * (box.min[a] + box.max[a]);
  return centre;
}

/// Refuses axis keys the dimension does not have, before the map is read.
void refuse_missing_axes(const Cursor& c, int dim) {
  if (!c.node().IsMap()) return;
  for (auto it = c.node().begin(); it != c.node().end(); ++it) {
    const auto axes = axis_names(3);
    const auto found = std::find(axes.begin(), axes.end(), it->first.Scalar());
    if (found != axes.end() && found - axes.begin() >= dim) {
      c.child(*found, it->second, it->first)
          .fail(fmt::format("axis '{}' does not exist in a {}D scene", *found, dim),
                join(axis_names(dim)));
    }
  }
}

/// The held components of a `velocity` or `displacement` condition (`what` names it): a number,
/// or a value over time (its value at t = 0 held, the function in `in_time`).
std::array<std::optional<double>, 3> read_held_components(const Cursor& c, int dim,
                                                          std::string_view what,
                                                          std::array<TimeFunction, 3>& in_time) {
  if (!c.node().IsMap())
    c.fail(fmt::format("a held {} is a map of the components it holds, got {} (e.g. "
                       "{}: {{{}: {}}}; a component left out stays free)",
                       what, c.describe(), what, axis_names(dim).back(),
                       what == "velocity" ? "5.0" : "1.0e-4"),
           "a map with keys " + join(axis_names(dim)));
  refuse_missing_axes(c, dim);
  const MapView map(c, axis_names(dim));
  if (map.entries().empty())
    c.fail(fmt::format("give at least one {} component", what), join(axis_names(dim)));
  std::array<std::optional<double>, 3> held;
  const auto axes = axis_names(dim);
  for (int a = 0; a < dim; ++a) {
    const auto component = map.get(axes[a]);
    if (!component) continue;
    if (component->node().IsMap()) {
      in_time[a] = read_time_function(*component, component->where().file);
      held[a] = in_time[a].at(0.0);
    } else {
      held[a] = component->number();
    }
  }
  return held;
}

InitialCondition read_initial_condition(const Cursor& c, int dim) {
  const MapView map(c, {"region", "velocity", "displacement", "strain", "origin", "gaussian"});
  InitialCondition ic;
  ic.region = read_shape(map.require("region"), dim);
  if (const auto v = map.get("velocity")) ic.velocity = v->point(dim);
  if (const auto u = map.get("displacement")) ic.displacement = u->point(dim);
  if (const auto e = map.get("strain")) ic.strain = e->point(dim);
  if (!ic.velocity && !ic.displacement && !ic.strain)
    c.fail("give at least one of velocity, displacement, strain");
  const auto origin = map.get("origin");
  if (ic.strain && !origin && !ic.region.bounds(dim).finite(dim))
    c.fail("the region is unbounded, so strain needs an explicit origin");
  ic.origin = origin ? origin->point(dim) : region_centre(ic.region, dim);
  if (const auto g = map.get("gaussian")) {
    if (!ic.velocity && !ic.displacement)
      g->fail("the gaussian envelope shapes velocity and displacement: give one of them");
    const MapView envelope(*g, {"center", "width", "axis"});
    ic.gaussian_center = envelope.require("center").point(dim);
    ic.gaussian_width = positive_number(envelope.require("width"));
    if (const auto axis = envelope.get("axis"))
      ic.gaussian_axis = static_cast<int>(axis->choice(axis_names(dim)));
  }
  return ic;
}

/// `fictitious_layer`: the face of the body's bounding box, x_min, x_max, y_min, ... .
void read_layer_face(const Cursor& c, int dim, BoundaryCondition& bc) {
  std::vector<std::string> faces;
  for (const auto& axis : axis_names(dim))
    faces.push_back(axis + "_min"), faces.push_back(axis + "_max");
  const auto k = static_cast<int>(c.choice(faces, "face"));
  bc.layer_axis = k / 2;
  bc.layer_side = k % 2 == 0 ? -1 : 1;
}

BoundaryCondition read_boundary_condition(const Cursor& c, int dim) {
  const MapView map(
      c, {"region", "velocity", "fixed", "traction", "normal", "displacement", "fictitious_layer"});
  BoundaryCondition bc;
  const auto layer = map.get("fictitious_layer");
  if (layer) {
    read_layer_face(*layer, dim, bc);
    if (const auto region = map.get("region"))
      region->fail("a fictitious layer lies outside the body's face: it takes no region",
                   "fictitious_layer: FACE, or region: SHAPE");
    if (const auto v = map.get("velocity"))
      v->fail("a fictitious layer holds displacements or tractions",
              "fixed, displacement or traction");
  } else {
    bc.region = read_shape(map.require("region"), dim);
  }
  const std::vector<std::string> kinds{"velocity", "fixed", "traction", "displacement"};
  const auto given =
      std::count_if(kinds.begin(), kinds.end(), [&](const std::string& k) { return map.has(k); });
  if (given != 1) {
    c.fail(given == 0 ? "a boundary condition needs one of velocity, fixed, traction, displacement"
                      : "give only one of velocity, fixed, traction, displacement per boundary "
                        "condition",
           join(kinds));
  }
  if (map.has("normal") && (!map.has("traction") || layer))
    map.get("normal")->fail(layer ? "a fictitious layer's normal is its face's axis"
                                  : "normal is only used with traction");
  if (const auto v = map.get("velocity")) {
    bc.kind = BoundaryCondition::Kind::Velocity;
    bc.velocity = read_held_components(*v, dim, "velocity", bc.in_time);
  } else if (const auto u = map.get("displacement")) {
    bc.kind = BoundaryCondition::Kind::Displacement;
    bc.displacement = read_held_components(*u, dim, "displacement", bc.in_time);
  } else if (const auto fixed = map.get("fixed")) {
    if (!fixed->boolean())
      fixed->fail("fixed must be true (leave the condition out to keep the region free)", "true");
    bc.kind = BoundaryCondition::Kind::Fixed;
  } else {
    bc.kind = BoundaryCondition::Kind::Traction;
    bc.traction = map.get("traction")->point(dim);
    bc.normal_axis =
        layer ? bc.layer_axis : static_cast<int>(map.require("normal").choice(axis_names(dim)));
  }
  return bc;
}

}  // namespace

std::vector<LocatedCrack> read_cracks(const Cursor& c, int dim) {
  std::vector<LocatedCrack> cracks;
  for (const auto& item : c.list()) {
    const auto points =
        dim == 2 ? item.list_of_size(2, "end points [[x0, y0], [x1, y1]]") : item.list();
    if (dim == 3 && points.size() < 3)
      item.fail(
          fmt::format("a 3D crack is a planar polygon of at least 3 corners "
                      "[[x, y, z], ...], got {}",
                      points.size()));
    LocatedCrack crack{{}, item.where()};
    for (const auto& p : points) crack.crack.points.push_back(p.point(dim));
    check_crack(item, crack.crack, dim);
    cracks.push_back(std::move(crack));
  }
  return cracks;
}

std::vector<Region> read_regions(const Cursor& c, int dim) {
  std::vector<Region> regions;
  for (const auto& item : c.list()) regions.push_back(Region{read_shape(item, dim), item.where()});
  return regions;
}

std::string material_name(const Cursor& c, const Scene& s) {
  std::vector<std::string> names;
  for (const auto& m : s.materials) names.push_back(m.name);
  const std::string name = c.string();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    const auto suggestion = closest_word(name, names);
    c.fail(fmt::format("material '{}' is not defined in materials{}", name,
                       suggestion ? fmt::format(", did you mean '{}'?", *suggestion) : ""),
           join(names));
  }
  return name;
}

std::vector<LocatedMaterialRegion> read_material_regions(const Cursor& c, const Scene& s) {
  std::vector<LocatedMaterialRegion> regions;
  for (const auto& item : c.list()) {
    const MapView map(item, {"region", "material"});
    LocatedMaterialRegion r;
    r.region = read_shape(map.require("region"), s.dimension);
    r.material = material_name(map.require("material"), s);
    r.where = item.where();
    regions.push_back(std::move(r));
  }
  return regions;
}

std::vector<LocatedInitialCondition> read_initial_conditions(const Cursor& c, int dim) {
  std::vector<LocatedInitialCondition> conditions;
  for (const auto& item : c.list())
    conditions.push_back({read_initial_condition(item, dim), item.where()});
  return conditions;
}

std::vector<LocatedBoundaryCondition> read_boundary_conditions(const Cursor& c, int dim) {
  std::vector<LocatedBoundaryCondition> conditions;
  for (const auto& item : c.list())
    conditions.push_back({read_boundary_condition(item, dim), item.where()});
  return conditions;
}

}  // namespace dhpd::scene::detail
