#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace scanplan {

// Whether (x, y) lies in the polygon (even-odd rule); points on an edge count as inside.
bool polygon_contains(const std::vector<Eigen::Vector2d>& corners, double x, double y);

// The area the operator wants mapped: a simple polygon in the map's x-y plane (paper §3.3,
// "target region"). A rectangle is the common case.
class TargetRegion {
 public:
  // The segmentation, the layers and the planner keep a grid over the region's bounding box
  // (0.5 m cells, 2 px a cell on the page): a region wider than this is a typo, and one of 1e9 m
  // would ask for more memory than the machine has (issue 16). A kilometre a side, four times
  // the paper's campus, is a large rescue site: 4 M cells, a 64 MB layer image.
  static constexpr double kMaxSideM = 1000.0;
  static constexpr std::size_t kMaxCorners = 1000;

  static TargetRegion rectangle(const Eigen::Vector2d& min, const Eigen::Vector2d& max);
  // Throws std::invalid_argument, saying what is wrong, for fewer than three corners or more than
  // kMaxCorners, a non-finite corner, a bounding box wider than kMaxSideM or no area.
  static TargetRegion polygon(std::vector<Eigen::Vector2d> corners);

  bool contains(double x, double y) const;
  const Eigen::Vector2d& min() const { return min_; }
  const Eigen::Vector2d& max() const { return max_; }
  const std::vector<Eigen::Vector2d>& corners() const { return corners_; }
  double area_m2() const;

 private:
  std::vector<Eigen::Vector2d> corners_;
  Eigen::Vector2d min_, max_;
};

// Whether (x, y) lies in one of `regions` (the operator's no-go zones).
bool in_any(const std::vector<TargetRegion>& regions, const Eigen::Vector2d& xy);

}  // namespace scanplan
