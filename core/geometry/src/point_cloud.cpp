#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

void PointCloud::append(const PointCloud& other) {
  // An empty cloud has no colours to disagree with; without this its empty colour array
  // would strip the colours from everything appended so far.
  if (other.empty()) return;
  const bool keep_colors = has_colors() || empty();
  points.insert(points.end(), other.points.begin(), other.points.end());
  if (keep_colors && other.has_colors()) {
    colors.insert(colors.end(), other.colors.begin(), other.colors.end());
  } else {
    colors.clear();
  }
}

Bounds3 bounds_of(const PointCloud& cloud) {
  Bounds3 b;
  for (const auto& p : cloud.points) b.extend(p);
  return b;
}

}  // namespace scanplan
