#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

struct GroundLevelConfig {
  // The ground compared lies within this of the scanner (x-y): near enough to be dense in both
  // clouds, far enough to hold many cells.
  double radius_m = 12.0;
  double cell_m = 1.0;
  // Fewer cells holding both clouds than this: no answer.
  int min_cells = 20;
};

// How far the scan must move up (z, metres) for its ground to lie on the map's: the median over
// x-y cells near the scanner of the difference of the lowest points of the two clouds. When the
// match is refused, x, y and yaw stay as the pose sensors said, but z need not: the ground
// fixes it, and a scan left at the reported height (σ 0.3 m) puts a false step into the map
// that splits the movable region. The lowest point of a cell is its ground wherever the ground
// was seen, and the median shrugs off the cells where it was not; an x-y error of a metre or
// two moves it by the ground's slope over that, centimetres on most sites.
// `target` and `scan_to_target` as register_scans takes them. Nothing when the clouds share
// too few cells.
std::optional<double> ground_offset(const PointCloud& target, const PointCloud& scan,
                                    const Eigen::Isometry3d& scan_to_target,
                                    const GroundLevelConfig& config = {});

}  // namespace scanplan
