#pragma once

#include <cstddef>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// What a real laser scanner returns that is not the scene, recognised without flags (issue 15):
//  - non-finite points (NaN or infinite coordinates: a reader's "no return");
//  - the scanner's own mount: nothing but the scanner itself lies within mount_radius_m of its
//    origin, and those returns move with the scanner, pulling every match towards no motion;
//  - a saturation shell: beams that saw nothing report the sensor's largest range (32.76 m on
//    the 3DTK SICK scans, ~1500 of 81k points), a sphere of phantom points at one range. A
//    real scene's ranges spread out; a share of at least min_saturated_share of the points
//    within saturation_band_m of the farthest range is taken for a shell and dropped.
// Ranges are measured from the scan frame's origin: the sensor for 3DTK data, the robot's base
// below it for ours (where a 0.3 m ball holds at most the ground under the robot's body).
struct ReturnFilterConfig {
  double mount_radius_m = 0.3;
  double saturation_band_m = 0.05;
  double min_saturated_share = 0.005;
  std::size_t min_saturated_points = 50;
};

struct DroppedReturns {
  std::size_t non_finite = 0;
  std::size_t mount = 0;
  std::size_t saturated = 0;
  std::size_t total() const { return non_finite + mount + saturated; }
};

// Drops those returns from `cloud` (colours kept in step) and says how many of each.
DroppedReturns drop_bad_returns(PointCloud& cloud, const ReturnFilterConfig& config = {});

}  // namespace scanplan
