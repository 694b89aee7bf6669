#include "scanplan/geometry/target_region.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace scanplan {

TargetRegion TargetRegion::rectangle(const Eigen::Vector2d& min, const Eigen::Vector2d& max) {
  return polygon({min, {max.x(), min.y()}, max, {min.x(), max.y()}});
}

TargetRegion TargetRegion::polygon(std::vector<Eigen::Vector2d> corners) {
  if (corners.size() < 3) throw std::invalid_argument("a target region needs at least 3 corners");
  if (corners.size() > kMaxCorners) {
    throw std::invalid_argument("a target region has at most " + std::to_string(kMaxCorners) +
                                " corners, got " + std::to_string(corners.size()));
  }
  TargetRegion r;
  r.min_ = r.max_ = corners.front();
  for (const auto& c : corners) {
    if (!c.allFinite()) throw std::invalid_argument("a target region corner is not finite");
    r.min_ = r.min_.cwiseMin(c);
    r.max_ = r.max_.cwiseMax(c);
  }
  const Eigen::Vector2d size = r.max_ - r.min_;
  if (size.maxCoeff() > kMaxSideM) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "a target region spans at most %.0f m a side, this one %.0f m by %.0f m",
                  kMaxSideM, size.x(), size.y());
    throw std::invalid_argument(buf);
  }
  r.corners_ = std::move(corners);
  if (r.area_m2() <= 0) throw std::invalid_argument("the target region encloses no area");
  return r;
}

bool polygon_contains(const std::vector<Eigen::Vector2d>& corners, double x, double y) {
  // Even-odd crossing count along +x; a point on an edge is inside, checked first because the
  // crossing count alone decides edge points by accident of rounding.
  bool inside = false;
  const std::size_t n = corners.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = corners[i];
    const Eigen::Vector2d& b = corners[j];
    const double cross = (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
    const bool within = std::min(a.x(), b.x()) <= x && x <= std::max(a.x(), b.x()) &&
                        std::min(a.y(), b.y()) <= y && y <= std::max(a.y(), b.y());
    if (within && std::abs(cross) <= 1e-12 * ((b - a).squaredNorm() + 1)) return true;
    if ((a.y() > y) != (b.y() > y) && x < a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

bool TargetRegion::contains(double x, double y) const {
  if (x < min_.x() || y < min_.y() || x > max_.x() || y > max_.y()) return false;
  return polygon_contains(corners_, x, y);
}

bool in_any(const std::vector<TargetRegion>& regions, const Eigen::Vector2d& xy) {
  return std::any_of(regions.begin(), regions.end(),
                     [&](const TargetRegion& r) { return r.contains(xy.x(), xy.y()); });
}

double TargetRegion::area_m2() const {
  double twice = 0;
  for (std::size_t i = 0, j = corners_.size() - 1; i < corners_.size(); j = i++) {
    twice += corners_[j].x() * corners_[i].y() - corners_[i].x() * corners_[j].y();
  }
  return std::abs(twice) / 2;
}

}  // namespace scanplan
