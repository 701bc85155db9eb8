// Reading a held component's value over time (docs/scenes.md, `boundary_conditions`; docs/
// theory.md §11): a number, {ramp: T, to: V}, or {table: [[t, v], ...]} or {table: FILE.csv}.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

namespace fs = std::filesystem;

/// (t, v) rows of a CSV file: two numbers a line; a first line that is not numbers is a header;
/// blank lines and lines starting with '#' are skipped.
std::vector<std::pair<double, double>> read_table_file(const Cursor& c, const std::string& path) {
  std::ifstream in(path);
  if (!in)
    c.fail(fmt::format("cannot open the table file '{}'", path), "a CSV file of t,value rows");
  std::vector<std::pair<double, double>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    double t = 0, v = 0;
    std::string rest;
    if (!(words >> t >> v) || (words >> rest)) {
      if (rows.empty() && number == 1) continue;  // a header
      c.fail(fmt::format("{}:{}: '{}' is not two numbers t,value", path, number, line),
             "a CSV file of t,value rows (an optional header line first)");
    }
    rows.emplace_back(t, v);
  }
  return rows;
}

}  // namespace

TimeFunction read_time_function(const Cursor& c, const std::string& scene_file) {
  const MapView map(c, {"ramp", "to", "table"});
  TimeFunction f;
  if (map.has("table") == (map.has("ramp") || map.has("to")))
    c.fail("a value over time is {ramp: T, to: V} or {table: ...}, not both",
           "a number, {ramp: T, to: V}, {table: [[t, v], ...]} or {table: FILE.csv}");
  if (const auto table = map.get("table")) {
    if (table->node().IsScalar()) {
      const fs::path given = table->string();
      const fs::path folder = fs::path(scene_file).parent_path();
      f.points = read_table_file(*table, (given.is_absolute() ? given : folder / given).string());
    } else {
      for (const auto& row : table->list()) {
        const auto pair = row.list_of_size(2, "a row [t, value]");
        f.points.emplace_back(pair[0].number(), pair[1].number());
      }
    }
    if (f.points.empty()) table->fail("the table has no row", "at least one [t, value] row");
    for (std::size_t k = 1; k < f.points.size(); ++k)
      if (!(f.points[k].first > f.points[k - 1].first))
        table->fail(fmt::format("the times must increase: row {} has t = {} after t = {}", k + 1,
                                f.points[k].first, f.points[k - 1].first),
                    "strictly increasing times");
    return f;
  }
  const double ramp = positive_number(map.require("ramp"));
  f.points = {{0.0, 0.0}, {ramp, map.require("to").number()}};
  return f;
}

}  // namespace dhpd::scene::detail
