#include "bvh.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace scanplan::detail {
namespace {

double half_area(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d e = (hi - lo).cwiseMax(0.0);
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

// Relative cost of testing one primitive against that of visiting one node.
constexpr double kItemCost = 1.5;
constexpr std::uint32_t kMaxLeafItems = 4;

}  // namespace

Bvh::Bvh(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi) {
  if (lo.size() != hi.size()) throw std::invalid_argument("Bvh: lo and hi differ in length");
  if (lo.empty()) return;
  items_.resize(lo.size());
  std::iota(items_.begin(), items_.end(), 0u);
  nodes_.reserve(2 * lo.size());
  nodes_.emplace_back();
  build(0, 0, static_cast<std::uint32_t>(items_.size()), 0, lo, hi);
}

void Bvh::build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth,
                const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi) {
  Eigen::Vector3d box_lo = Eigen::Vector3d::Constant(kInf), box_hi = -box_lo;
  for (std::uint32_t i = begin; i < end; ++i) {
    box_lo = box_lo.cwiseMin(lo[items_[i]]);
    box_hi = box_hi.cwiseMax(hi[items_[i]]);
  }
  nodes_[node].lo = box_lo;
  nodes_[node].hi = box_hi;
  const std::uint32_t n = end - begin;
  const auto make_leaf = [&] {
    nodes_[node].first = begin;
    nodes_[node].count = n;
  };
  if (n <= 1 || depth >= kMaxDepth - 2) return make_leaf();

  // Full-sweep surface-area heuristic: the worlds hold hundreds of primitives, not millions,
  // so sorting along each axis is cheap and gives the best trees.
  const auto centre = [&](std::uint32_t item, int axis) { return lo[item][axis] + hi[item][axis]; };
  double best_cost = kInf;
  int best_axis = -1;
  std::uint32_t best_split = 0;
  std::vector<double> right_area(n);
  for (int axis = 0; axis < 3; ++axis) {
    std::sort(items_.begin() + begin, items_.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
      return centre(a, axis) < centre(b, axis) || (centre(a, axis) == centre(b, axis) && a < b);
    });
    Eigen::Vector3d rlo = Eigen::Vector3d::Constant(kInf), rhi = -rlo;
    for (std::uint32_t k = n; k-- > 1;) {
      rlo = rlo.cwiseMin(lo[items_[begin + k]]);
      rhi = rhi.cwiseMax(hi[items_[begin + k]]);
      right_area[k] = half_area(rlo, rhi);
    }
    Eigen::Vector3d llo = Eigen::Vector3d::Constant(kInf), lhi = -llo;
    for (std::uint32_t k = 1; k < n; ++k) {
      llo = llo.cwiseMin(lo[items_[begin + k - 1]]);
      lhi = lhi.cwiseMax(hi[items_[begin + k - 1]]);
      const double cost = half_area(llo, lhi) * k + right_area[k] * (n - k);
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_split = k;
      }
    }
  }
  const double parent_area = half_area(box_lo, box_hi);
  const double split_cost = 1.0 + kItemCost * best_cost / std::max(parent_area, 1e-300);
  if (n <= kMaxLeafItems && split_cost >= kItemCost * n) return make_leaf();

  std::sort(items_.begin() + begin, items_.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
    return centre(a, best_axis) < centre(b, best_axis) ||
           (centre(a, best_axis) == centre(b, best_axis) && a < b);
  });
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  nodes_[node].axis = best_axis;
  build(left, begin, begin + best_split, depth + 1, lo, hi);
  build(left + 1, begin + best_split, end, depth + 1, lo, hi);
}

}  // namespace scanplan::detail
