// `--set key.path=value`: replaces one node of the scene tree before it is read and checked.
#include <fmt/format.h>
#include <array>

#include <algorithm>
#include <cctype>

#include "tools/scene/detail.hpp"

namespace dhpd::scene {

Override parse_override(std::string_view text) {
  const auto equals = text.find('=');
  if (equals == std::string_view::npos || equals == 0) {
    fail(Location{std::string(detail::kOverrideSource), 0, std::string(text)},
         "expected key.path=value, e.g. --set time.end=2e-5");
  }
  return Override{std::string(text.substr(0, equals)), std::string(text.substr(equals + 1))};
}

namespace detail {
namespace {

Location at_override(const std::string& path) {
  return Location{std::string(kOverrideSource), 0, path};
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = path.find('.', start);
    parts.push_back(path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (parts.back().empty()) fail(at_override(path), "empty key in the path");
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

/// Position `part` names in the list `list`, or a failure naming the override.
std::size_t list_index(const YAML::Node& list, const std::string& part, const std::string& prefix,
                       const std::string& path) {
  const bool digits = std::all_of(
      part.begin(), part.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
  if (!digits || part.size() > 9) {
    fail(at_override(path),
         fmt::format("'{}' is a list: use an item number, not '{}'", prefix, part));
  }
  const std::size_t index = std::stoul(part);
  if (index >= list.size()) {
    fail(at_override(path),
         fmt::format("item {} is out of range: '{}' has {} item{}", index, prefix, list.size(),
                     list.size() == 1 ? "" : "s"),
         list.size() == 0 ? "" : fmt::format("0 to {}", list.size() - 1));
  }
  return index;
}

/// The value under `key` in the map `map` (first occurrence), if present.
std::optional<YAML::Node> map_value(const YAML::Node& map, const std::string& key) {
  if (!map.IsMap()) return std::nullopt;
  for (auto it = map.begin(); it != map.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
  return std::nullopt;
}

std::string describe_node(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  return fmt::format("the value '{}'", node.Scalar());
}

/// Puts `value` at `parts` below `node`, creating missing map keys; returns the canonical path.
std::string assign(YAML::Node node, const std::vector<std::string>& parts, const YAML::Node& value,
                   const std::string& path) {
  std::string prefix;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const bool last = i + 1 == parts.size();
    const std::string& part = parts[i];
    if (node.IsSequence()) {
      const std::size_t index = list_index(node, part, prefix, path);
      if (!prefix.empty()) prefix += '.';
      prefix += std::to_string(index);
      if (last) {
        node[index] = value;
      } else {
        node.reset(node[index]);
      }
      continue;
    }
    if (!node.IsMap() && !node.IsNull()) {
      fail(at_override(path), fmt::format("cannot set '{}' inside '{}': it holds {}, not a map",
                                          part, prefix, describe_node(node)));
    }
    prefix += (prefix.empty() ? "" : ".") + part;
    auto existing = map_value(node, part);
    if (last) {
      if (existing) {
        existing->operator=(value);
      } else {
        node[part] = value;
      }
    } else if (existing) {
      node.reset(*existing);
    } else {
      node[part] = YAML::Node(YAML::NodeType::Map);
      node.reset(*map_value(node, part));
    }
  }
  return prefix;
}

/// Keys that exclude each other: setting one by override drops the other, so that
/// `--set time.steps=50` shortens a scene that gives `time.end` (and `output.every` replaces
/// `output.frames`) instead of being refused as "both given".
void drop_exclusive_sibling(YAML::Node& root, const std::string& path) {
  static constexpr std::array<std::array<const char*, 3>, 4> kExclusive = {{
      {"time.steps", "time", "end"},
      {"time.end", "time", "steps"},
      {"output.every", "output", "frames"},
      {"output.frames", "output", "every"},
  }};
  for (const auto& [set, parent, other] : kExclusive) {
    if (path != set) continue;
    YAML::Node map = root[parent];
    if (map.IsMap() && map[other]) map.remove(other);
  }
}

}  // namespace

std::vector<std::string> apply_overrides(YAML::Node& root, const std::vector<Override>& overrides) {
  std::vector<std::string> paths;
  for (const auto& override_item : overrides) {
    const auto parts = split_path(override_item.path);
    YAML::Node value;
    try {
      value = YAML::Load(override_item.value);
    } catch (const YAML::ParserException& e) {
      fail(at_override(override_item.path),
           fmt::format("cannot read the value '{}' as YAML: {}", override_item.value, e.msg));
    }
    if (const auto problem = find_tree_problem(value))
      fail(at_override(override_item.path),
           fmt::format("cannot use the value '{}': {}{}", override_item.value,
                       problem->path.empty() ? "" : problem->path + ": ", problem->message));
    paths.push_back(assign(root, parts, value, override_item.path));
    drop_exclusive_sibling(root, paths.back());
  }
  return paths;
}

}  // namespace detail
}  // namespace dhpd::scene
