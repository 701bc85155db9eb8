// Hostile YAML trees: anchors and aliases can make a short file stand for a cyclic tree (an alias
// inside the value it names) or an exponentially large one ("billion laughs"). Both are refused
// before any value is read, so the reader never recurses forever or expands without bound.
#include <fmt/format.h>

#include <unordered_set>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

class TreeWalk {
 public:
  explicit TreeWalk(const YAML::Node& root) { visit(root); }
  std::optional<TreeProblem> problem;

 private:
  std::vector<YAML::Node> ancestors_;
  std::vector<std::string> path_;  ///< key path of the value being visited
  std::unordered_set<int> seen_positions_;
  std::size_t repeats_ = 0;

  static int line_of(const YAML::Node& node) {
    return node.Mark().is_null() ? 0 : node.Mark().line + 1;
  }

  void report(const YAML::Node& node, std::string message) {
    std::string path;
    for (const auto& part : path_) path += (path.empty() ? "" : ".") + part;
    problem = TreeProblem{line_of(node), std::move(path), std::move(message)};
  }

  void visit_child(const YAML::Node& node, std::string part) {
    path_.push_back(std::move(part));
    visit(node);
    path_.pop_back();
  }

  bool inside_itself(const YAML::Node& node) const {
    for (const auto& a : ancestors_)
      if (a.is(node)) return true;
    return false;
  }

  void visit(const YAML::Node& node) {
    if (problem) return;
    if (inside_itself(node)) {
      report(node,
             "an alias stands for a value that contains this alias: the tree would be "
             "infinite");
      return;
    }
    if (ancestors_.size() >= kMaxSceneDepth) {
      report(node, fmt::format("values are nested more than {} levels deep", kMaxSceneDepth));
      return;
    }
    // A node reached again (same position in the text) is an alias being expanded.
    if (!node.Mark().is_null() && !seen_positions_.insert(node.Mark().pos).second &&
        ++repeats_ > kMaxAliasExpansion) {
      report(node, fmt::format("aliases expand to more than {} repeated values (anchors used "
                               "inside each other)",
                               kMaxAliasExpansion));
      return;
    }
    if (!node.IsMap() && !node.IsSequence()) return;
    ancestors_.push_back(node);
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) visit_child(node[i], std::to_string(i));
    } else {
      for (const auto& entry : node) {
        visit(entry.first);
        visit_child(entry.second, entry.first.IsScalar() ? entry.first.Scalar() : "?");
      }
    }
    ancestors_.pop_back();
  }
};

}  // namespace

std::optional<TreeProblem> find_tree_problem(const YAML::Node& root) {
  return TreeWalk(root).problem;
}

}  // namespace dhpd::scene::detail
