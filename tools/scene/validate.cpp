// Value checks of the scene reader: physical ranges, shapes of boxes, cracks and the Poisson ratio.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/physics/material_law.hpp"
#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {

double positive_number(const Cursor& c) {
  const double value = c.number();
  if (!(value > 0.0)) c.fail(fmt::format("{} must be > 0, got {}", c.key(), c.text()), "> 0");
  return value;
}

double non_negative_number(const Cursor& c) {
  const double value = c.number();
  if (value < 0.0) c.fail(fmt::format("{} must be >= 0, got {}", c.key(), c.text()), ">= 0");
  return value;
}

std::int64_t positive_integer(const Cursor& c) {
  const std::int64_t value = c.integer();
  if (value <= 0) {
    c.fail(fmt::format("{} must be an integer > 0, got {}", c.key(), c.text()), "integers >= 1");
  }
  return value;
}

double horizon_factor(const Cursor& c) {
  const double value = c.number();
  if (value < 1.0) {
    c.fail(
        fmt::format("the horizon factor (horizon / spacing) must be at least 1, got {}", c.text()),
        ">= 1; 3.015 is the usual choice");
  }
  return value;
}

double safety_factor(const Cursor& c) {
  const double value = c.number();
  if (!(value > 0.0 && value <= 1.0)) {
    c.fail(fmt::format("safety must lie in (0, 1], got {}", c.text()), "0 < safety <= 1");
  }
  return value;
}

int dimension(const Cursor& c) {
  const std::int64_t value = c.integer();
  if (value < 1 || value > 3) {
    c.fail(fmt::format("dimension must be 1, 2 or 3, got {}", c.text()), "1, 2, 3");
  }
  return static_cast<int>(value);
}

std::string scene_name(const Cursor& c) {
  const std::string name = c.string();
  const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.' || ch == '-';
  });
  if (!valid || name == "." || name == "..") {
    c.fail(fmt::format("name '{}' cannot be used in output file names", name),
           "letters, digits, '_', '.', '-'");
  }
  return name;
}

void check_box(const Cursor& at, const geometry::Box& box, int dim) {
  const auto axes = axis_names(dim);
  for (int a = 0; a < dim; ++a) {
    if (!(box.max[a] > box.min[a])) {
      at.fail(
          fmt::format("max must be greater than min on every axis, but on {} max = {} <= min "
                      "= {}",
                      axes[a], box.max[a], box.min[a]));
    }
  }
}

void check_spacing(const Cursor& at, double spacing, const geometry::Box& box, int dim) {
  double smallest = box.max[0] - box.min[0];
  for (int a = 1; a < dim; ++a) smallest = std::min(smallest, box.max[a] - box.min[a]);
  if (spacing > smallest) {
    at.fail(fmt::format("{} {} is larger than the part's smallest extent {}", at.key(), spacing,
                        smallest),
            fmt::format("0 < {} <= {}", at.key(), smallest));
  }
  // Particles are counted with 32-bit integers; a spacing that asks for more cells than that
  // would otherwise try to fill memory (or overflow the lattice's cell counts).
  constexpr double kMaxCells = 2147483647.0;
  double cells = 1.0, volume = 1.0;
  for (int a = 0; a < dim; ++a) {
    cells *= (box.max[a] - box.min[a]) / spacing;
    volume *= box.max[a] - box.min[a];
  }
  if (!(cells <= kMaxCells)) {
    at.fail(fmt::format("{} {} makes about {:.3g} cells in this part, more than the {:.0f} "
                        "particles a run can hold",
                        at.key(), spacing, cells, kMaxCells),
            fmt::format("{} >= {:.3g}", at.key(), std::pow(volume / kMaxCells, 1.0 / dim)));
  }
}

void check_poisson(const Cursor& at, double nu, const Section& section) {
  const double implied = implied_poisson_ratio(section);
  constexpr double kTolerance = 1e-6;
  if (std::abs(nu - implied) > kTolerance) {
    const std::string model = section.dim == 2
                                  ? fmt::format("2D plane {}", to_string(section.plane))
                                  : fmt::format("{}D", section.dim);
    at.fail(fmt::format("bond-based peridynamics fixes nu = {:.6g} in {}, got {}; omit nu or give "
                        "the implied value",
                        implied, model, at.text()),
            fmt::format("{:.10g}", implied));
  }
}

double state_poisson_ratio(const Cursor& at, int dim) {
  if (dim == 1)
    at.fail("a 1D bar has no Poisson effect: the state-based model takes E alone", "(omit nu)");
  const double nu = at.number();
  if (!(nu > -1.0 && nu < 0.5))
    at.fail(fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", at.text()),
            "-1 < nu < 0.5");
  return nu;
}

void check_crack(const Cursor& at, const geometry::Crack& crack, int dim) {
  if (dim == 2) {
    if (crack.points[0] == crack.points[1]) at.fail("the two end points of the crack coincide");
    return;
  }
  if (!geometry::is_planar(crack)) {
    at.fail("the corners of a 3D crack must lie in one plane and span a polygon of non-zero area");
  }
}

}  // namespace dhpd::scene::detail
