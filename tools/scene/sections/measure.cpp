// Reading the `measure` block (docs/scenes.md, `measure`; docs/theory.md §15): thresholds,
// intervals, notch tips and the published values echoed into summary.json.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {

std::string csv_name(const Cursor& c, std::string_view what) {
  const std::string name = c.string();
  const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.' || ch == '-';
  });
  if (!valid)
    c.fail(fmt::format("{} name '{}' cannot be written as a CSV cell or column", what, name),
           "letters, digits, '_', '.', '-'");
  return name;
}

namespace {

double damage_threshold(const Cursor& c) {
  const double value = c.number();
  if (!(value > 0.0 && value < 1.0))
    c.fail(fmt::format("damage_threshold must lie in (0, 1), got {}", c.text()),
           "0 < damage_threshold < 1");
  return value;
}

void read_tips(const Cursor& c, int dim, MeasureSpec& spec) {
  const auto items = c.list();
  if (items.empty())
    c.fail("give at least one notch tip", "a list of {name: ..., at: [...], direction: [...]}");
  std::vector<Location> names;
  for (const auto& item : items) {
    const MapView map(item, {"name", "at", "direction", "front", "region"});
    const Cursor name = map.require("name");
    measure::Tip tip;
    tip.name = csv_name(name, "tip");
    for (std::size_t k = 0; k < spec.settings.tips.size(); ++k)
      if (spec.settings.tips[k].name == tip.name)
        name.fail(names[k].line > 0
                      ? fmt::format("duplicate tip name '{}' (first given on line {})", tip.name,
                                    names[k].line)
                      : fmt::format("duplicate tip name '{}'", tip.name));
    const Cursor at = map.require("at");
    tip.at = at.point(dim);
    tip.direction = nonzero_vector(map.require("direction"), dim);
    if (const auto front = map.get("front")) {
      if (dim != 3) front->fail("front is the notch front's direction of a 3D scene", "3D only");
      tip.front = nonzero_vector(*front, dim);
    }
    if (const auto region = map.get("region")) {
      tip.region = read_shape(*region, dim);
      if (!tip.region->contains(tip.at, dim))
        region->fail(fmt::format("the notch tip [{}] lies outside its region",
                                 fmt::join(tip.at.begin(), tip.at.begin() + dim, ", ")),
                     "a region that holds the notch tip");
    }
    names.push_back(name.where());
    spec.tip_at.push_back(at.where());
    spec.settings.tips.push_back(std::move(tip));
  }
}

/// A number as published: integers written as such stay integers in summary.json.
measure::Published published_number(const Cursor& c) {
  measure::Published out;
  out.kind = measure::Published::Kind::Number;
  out.number = c.number();
  const std::string& text = c.node().Scalar();
  const std::size_t sign = !text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0;
  constexpr std::size_t kInt64Digits = 18;  // fits an int64 whatever the digits
  out.integer = text.size() > sign && text.size() - sign <= kInt64Digits &&
                text.find_first_not_of("0123456789", sign) == std::string::npos;
  return out;
}

measure::Published read_published(const Cursor& c, bool top) {
  measure::Published out;
  if (c.node().IsSequence()) {
    out.kind = measure::Published::Kind::List;
    for (const auto& item : c.list()) out.list.push_back(item.number());
    return out;
  }
  if (!top && c.node().IsScalar()) return published_number(c);
  if (!c.node().IsMap() && !c.node().IsNull())
    c.fail(fmt::format("expected a map of names to published values, got {}", c.describe()),
           "numbers, lists of numbers, or maps of those");
  const MapView map(c, {});
  for (const auto& [key, value] : map.entries()) {
    out.keys.push_back(key);
    out.values.push_back(read_published(value, false));
  }
  return out;
}

}  // namespace

MeasureSpec read_measure(const Cursor& c, const Scene& s) {
  const MapView map(
      c, {"damage_threshold", "every", "smoothing", "branch_separation", "tips", "published"});
  if (!s.effects.fracture)
    c.fail("measure follows cracks through the damage field, which needs effects.fracture: true",
           "effects: {fracture: true}");
  MeasureSpec spec;
  spec.where = c.where();
  auto& m = spec.settings;
  if (const auto v = map.get("damage_threshold")) m.damage_threshold = damage_threshold(*v);
  if (const auto v = map.get("every")) m.every = positive_integer(*v);
  if (const auto v = map.get("smoothing")) m.smoothing = positive_integer(*v);
  if (const auto v = map.get("branch_separation")) m.branch_separation = positive_number(*v);
  read_tips(map.require("tips"), s.dimension, spec);
  if (const auto v = map.get("published")) spec.published = read_published(*v, true);
  return spec;
}

}  // namespace dhpd::scene::detail
