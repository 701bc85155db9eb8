// Reader of particle files `x y [z] volume [material]` with file:line messages.
#include "tools/scene/points_file.hpp"

#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/base/errors.hpp"

namespace dhpd::scene {

using geometry::PointSet;
using geometry::Vec3;
namespace {

struct LineSource {
  const std::string& name;
  int line;
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(fmt::format("{}:{}: {}", name, line, message));
  }
};

std::vector<std::string> split_columns(const std::string& text) {
  std::istringstream in(text.substr(0, text.find('#')));
  std::vector<std::string> columns;
  for (std::string word; in >> word;) columns.push_back(word);
  return columns;
}

std::optional<double> parse_number(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return {};
  if (!std::isfinite(value)) return {};
  return value;
}

double number_at(const LineSource& at, const std::vector<std::string>& columns, std::size_t k,
                 const char* what) {
  const auto value = parse_number(columns[k]);
  if (!value)
    at.fail(fmt::format("column {} ({}): '{}' is not a finite number", k + 1, what, columns[k]));
  return *value;
}

int material_at(const LineSource& at, const std::string& word, const PointsFileOptions& o) {
  for (std::size_t m = 0; m < o.materials.size(); ++m)
    if (o.materials[m] == word) return static_cast<int>(m);
  int index = -1;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), index);
  const bool is_index = error == std::errc() && end == word.data() + word.size();
  if (is_index && index >= 0 && static_cast<std::size_t>(index) < o.materials.size()) return index;
  std::string known;
  for (std::size_t m = 0; m < o.materials.size(); ++m)
    known += fmt::format("{}{} ({})", m ? ", " : "", o.materials[m], m);
  at.fail(fmt::format("unknown material {} '{}' (allowed: {})", is_index ? "index" : "name", word,
                      known));
}

void read_line(const LineSource& at, const std::vector<std::string>& columns,
               const PointsFileOptions& o, PointSet& out) {
  const auto dim = static_cast<std::size_t>(o.dim);
  if (columns.size() != dim + 1 && columns.size() != dim + 2) {
    const char* axes = o.dim == 1 ? "x" : (o.dim == 2 ? "x y" : "x y z");
    at.fail(fmt::format("expected {} or {} columns ({} volume [material]), got {}", dim + 1,
                        dim + 2, axes, columns.size()));
  }
  Vec3 x{0, 0, 0};
  const char* names[3] = {"x", "y", "z"};
  for (std::size_t a = 0; a < dim; ++a) x[a] = number_at(at, columns, a, names[a]);
  const double volume = number_at(at, columns, dim, "volume");
  if (!(volume > 0.0)) at.fail(fmt::format("volume must be > 0, got {}", columns[dim]));
  int material = 0;
  if (columns.size() == dim + 2) {
    material = material_at(at, columns[dim + 1], o);
  } else if (o.default_material) {
    material = *o.default_material;
  } else {
    at.fail("no material column and no default material: add the material as the last column");
  }
  const double measure = volume / o.section;
  // A volume far from the section's scale over- or underflows: no particle may get a cell
  // measure of 0 or infinity.
  if (!(std::isfinite(measure) && measure > 0.0))
    at.fail(
        fmt::format("volume {} divided by the section {:g} (the thickness in 2D, the area "
                    "in 1D) gives a cell measure of {:g}, which is not a finite number > 0",
                    columns[dim], o.section, measure));
  out.position.push_back(x);
  out.cell_measure.push_back(measure);
  out.spacing.push_back(geometry::point_size(measure, o.dim, o.size_rule));
  out.material.push_back(material);
  out.part.push_back(o.part);
}

}  // namespace

PointSet parse_points(std::istream& in, const std::string& name, const PointsFileOptions& o) {
  if (o.dim < 1 || o.dim > 3 || !(o.section > 0.0))
    throw EngineError("points file options: dimension 1 to 3 and section > 0 expected");
  PointSet out;
  int line = 0;
  for (std::string text; std::getline(in, text);) {
    ++line;
    const auto columns = split_columns(text);
    if (!columns.empty()) read_line(LineSource{name, line}, columns, o, out);
  }
  if (out.size() == 0)
    throw InputError(
        fmt::format("{}: the points file holds no point (expected lines of "
                    "'x{} volume [material]')",
                    name, o.dim == 1 ? "" : (o.dim == 2 ? " y" : " y z")));
  return out;
}

PointSet read_points_file(const std::string& path, const PointsFileOptions& options) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the points file", path));
  return parse_points(in, path, options);
}

}  // namespace dhpd::scene
