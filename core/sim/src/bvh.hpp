#pragma once

// A bounding-volume hierarchy over axis-aligned boxes, for the ray caster's solids. It knows
// nothing of what the boxes hold: traversal hands each candidate's index to the caller, who
// tests the real shape and may shorten the ray.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ray_primitives.hpp"

namespace scanplan::detail {

class Bvh {
 public:
  Bvh() = default;  // holds nothing
  // Item i is bounded by [lo[i], hi[i]].
  Bvh(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi);

  // Calls `visit(item)` for every item whose box the ray meets within [t_min, t_max], nearer
  // subtrees first; `visit` lowers t_max (the caller's variable) when it finds a hit, which
  // prunes whatever lies behind.
  template <class Visit>
  void traverse(const Ray& ray, double t_min, double& t_max, Visit&& visit) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[kMaxDepth];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!overlaps(node.lo, node.hi, ray, t_min, t_max)) continue;
      if (node.count > 0) {
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) visit(items_[i]);
        continue;
      }
      // Children sit next to each other; the one whose centre lies further along the ray is
      // pushed first so the nearer one is searched first and shortens the ray for the other.
      const std::uint32_t left = node.first, right = node.first + 1;
      const bool right_first = ray.dir[node.axis] < 0;
      stack[top++] = right_first ? left : right;
      stack[top++] = right_first ? right : left;
    }
  }

  std::size_t node_count() const { return nodes_.size(); }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    std::uint32_t first = 0;  // leaf: first item in items_; inner: index of the left child
    std::uint32_t count = 0;  // items in a leaf; 0 for an inner node
    int axis = 0;             // the split axis of an inner node
  };
  // A depth the build never exceeds (it stops splitting well before); the traversal stack
  // holds at most one pending sibling per level.
  static constexpr int kMaxDepth = 64;

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth,
             const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi);

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> items_;
};

}  // namespace scanplan::detail
