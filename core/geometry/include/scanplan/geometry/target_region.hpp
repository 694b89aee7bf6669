#pragma once

#include <Eigen/Core>
#include <vector>

namespace scanplan {

// Whether (x, y) lies in the polygon (even-odd rule); points on an edge count as inside.
bool polygon_contains(const std::vector<Eigen::Vector2d>& corners, double x, double y);

// The area the operator wants mapped: a simple polygon in the map's x-y plane (paper §3.3,
// "target region"). A rectangle is the common case.
class TargetRegion {
 public:
  static TargetRegion rectangle(const Eigen::Vector2d& min, const Eigen::Vector2d& max);
  // Throws std::invalid_argument for fewer than three corners or a non-finite one.
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

}  // namespace scanplan
