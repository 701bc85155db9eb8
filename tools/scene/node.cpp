// Typed access to scene YAML nodes: every conversion failure names file, line and key path.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

#include "engine/base/errors.hpp"
#include "tools/scene/detail.hpp"

namespace dhpd::scene {

void fail(const Location& where, std::string_view message, std::string_view allowed) {
  std::string text;
  if (where.line > 0) {
    text = fmt::format("{}:{}: ", where.file, where.line);
  } else if (where.file == detail::kOverrideSource && !where.path.empty()) {
    text = fmt::format("{} ", where.file);
  } else if (!where.file.empty()) {
    text = fmt::format("{}: ", where.file);
  }
  if (!where.path.empty()) text += fmt::format("{}: ", where.path);
  text += message;
  if (!allowed.empty()) text += fmt::format(" (allowed: {})", allowed);
  throw InputError(text);
}

namespace detail {
namespace {

/// Optimal-string-alignment distance (a swap of neighbours counts once), case-insensitive.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  auto lower = [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  };
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1]))
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

/// Plain-scalar text parsed as a double, or nothing when it is not a number.
std::optional<double> parse_double(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::optional<std::int64_t> parse_integer(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

bool is_quoted(const YAML::Node& node) {
  return node.Tag() == "!";
}

}  // namespace

std::string join(const std::vector<std::string>& words) {
  return fmt::format("{}", fmt::join(words, ", "));
}

std::optional<std::string> closest_word(std::string_view word,
                                        const std::vector<std::string>& candidates) {
  const std::size_t limit = word.size() <= 3 ? 1 : 2;
  std::optional<std::string> best;
  std::size_t best_distance = limit + 1;
  for (const auto& candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d < best_distance && d < word.size()) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
}

std::vector<std::string> axis_names(int dim) {
  const std::vector<std::string> all{"x", "y", "z"};
  return {all.begin(), all.begin() + std::clamp(dim, 0, 3)};
}

Cursor::Cursor(const Source& source, YAML::Node node, std::string path, int line, bool overridden)
    : source_(&source),
      node_(std::move(node)),
      path_(std::move(path)),
      line_(line),
      overridden_(overridden) {}

Cursor Cursor::root(const Source& source, const YAML::Node& node) {
  const int line = node.Mark().is_null() ? 1 : node.Mark().line + 1;
  return Cursor(source, node, "", line, false);
}

std::string_view Cursor::key() const {
  const auto dot = path_.rfind('.');
  return dot == std::string::npos ? std::string_view(path_)
                                  : std::string_view(path_).substr(dot + 1);
}

Location Cursor::where() const {
  if (overridden_) return Location{std::string(kOverrideSource), 0, path_};
  return Location{source_->file, line_, path_};
}

void Cursor::fail(std::string_view message, std::string_view allowed) const {
  scene::fail(where(), message, allowed);
}

Cursor Cursor::child(std::string key, const YAML::Node& value, const YAML::Node& key_node) const {
  std::string path = path_.empty() ? key : path_ + "." + key;
  const auto& paths = source_->override_paths;
  const bool from_command_line = overridden_ || key_node.Mark().is_null() ||
                                 std::find(paths.begin(), paths.end(), path) != paths.end();
  const int line = key_node.Mark().is_null() ? 0 : key_node.Mark().line + 1;
  return Cursor(*source_, value, std::move(path), line, from_command_line);
}

Cursor Cursor::element(std::size_t index, const YAML::Node& value) const {
  std::string path = fmt::format("{}.{}", path_, index);
  const auto& paths = source_->override_paths;
  const bool from_command_line =
      overridden_ || std::find(paths.begin(), paths.end(), path) != paths.end();
  const int line = value.Mark().is_null() ? line_ : value.Mark().line + 1;
  return Cursor(*source_, value, std::move(path), line, from_command_line);
}

std::string Cursor::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsSequence()) return "a list";
  if (node_.IsMap()) return "a map";
  return fmt::format("'{}'", node_.Scalar());
}

std::string Cursor::text() const {
  return node_.IsScalar() ? node_.Scalar() : describe();
}

double Cursor::number() const {
  const auto value =
      node_.IsScalar() && !is_quoted(node_) ? parse_double(node_.Scalar()) : std::nullopt;
  if (!value) fail(fmt::format("expected a number, got {}", describe()));
  if (!std::isfinite(*value)) fail(fmt::format("expected a finite number, got {}", describe()));
  return *value;
}

std::int64_t Cursor::integer() const {
  if (node_.IsScalar() && !is_quoted(node_)) {
    if (const auto exact = parse_integer(node_.Scalar())) return *exact;
    const auto real = parse_double(node_.Scalar());
    constexpr double kLimit = 9.0e18;
    if (real && std::isfinite(*real) && std::abs(*real) < kLimit && std::floor(*real) == *real)
      return static_cast<std::int64_t>(*real);
  }
  fail(fmt::format("expected an integer, got {}", describe()));
}

bool Cursor::boolean() const {
  if (node_.IsScalar() && !is_quoted(node_)) {
    const std::string& text = node_.Scalar();
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
  }
  fail(fmt::format("expected true or false, got {}", describe()));
}

std::string Cursor::string() const {
  if (!node_.IsScalar()) fail(fmt::format("expected a string, got {}", describe()));
  return node_.Scalar();
}

std::vector<Cursor> Cursor::list() const {
  if (node_.IsNull()) return {};
  if (!node_.IsSequence()) fail(fmt::format("expected a list, got {}", describe()));
  std::vector<Cursor> items;
  for (std::size_t i = 0; i < node_.size(); ++i) items.push_back(element(i, node_[i]));
  return items;
}

std::vector<Cursor> Cursor::list_of_size(std::size_t size, std::string_view what) const {
  if (!node_.IsSequence())
    fail(fmt::format("expected a list of {} {}, got {}", size, what, describe()));
  if (node_.size() != size)
    fail(fmt::format("expected a list of {} {}, got {} item{}", size, what, node_.size(),
                     node_.size() == 1 ? "" : "s"));
  return list();
}

geometry::Vec3 Cursor::point(int dim) const {
  geometry::Vec3 p{0, 0, 0};
  const auto items = list_of_size(static_cast<std::size_t>(dim), "numbers (one per axis)");
  for (int a = 0; a < dim; ++a) p[a] = items[a].number();
  return p;
}

std::size_t Cursor::choice(const std::vector<std::string>& allowed, std::string_view what) const {
  const std::string word = string();
  const auto found = std::find(allowed.begin(), allowed.end(), word);
  if (found != allowed.end()) return static_cast<std::size_t>(found - allowed.begin());
  const auto suggestion = closest_word(word, allowed);
  fail(fmt::format("unknown {} '{}'{}", what.empty() ? key() : what, word,
                   suggestion ? fmt::format(", did you mean '{}'?", *suggestion) : ""),
       join(allowed));
}

MapView::MapView(const Cursor& map, const std::vector<std::string>& allowed) : self_(map) {
  const YAML::Node& node = map.node();
  if (node.IsNull()) return;
  if (!node.IsMap()) map.fail(fmt::format("expected a map of keys, got {}", map.describe()));
  for (auto it = node.begin(); it != node.end(); ++it) {
    if (!it->first.IsScalar()) map.fail("map keys must be plain words");
    const std::string key = it->first.Scalar();
    Cursor value = map.child(key, it->second, it->first);
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      const auto suggestion = closest_word(key, allowed);
      value.fail(fmt::format("unknown key '{}'{}", key,
                             suggestion ? fmt::format(", did you mean '{}'?", *suggestion) : ""),
                 join(allowed));
    }
    if (const auto first = get(key)) {
      const Location before = first->where();
      value.fail(before.line > 0
                     ? fmt::format("duplicate key '{}' (first given on line {})", key, before.line)
                     : fmt::format("duplicate key '{}'", key));
    }
    entries_.emplace_back(key, std::move(value));
  }
}

std::optional<Cursor> MapView::get(std::string_view key) const {
  for (const auto& [name, value] : entries_)
    if (name == key) return value;
  return std::nullopt;
}

Cursor MapView::require(std::string_view key) const {
  if (auto value = get(key)) return *value;
  self_.fail(fmt::format("missing required key '{}'", key));
}

}  // namespace detail
}  // namespace dhpd::scene
