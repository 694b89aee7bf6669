#pragma once

#include <cstddef>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// What a real laser scanner returns that is not the scene, recognised without flags (issue 15):
//  - non-finite points (NaN or infinite coordinates: a reader's "no return");
//  - the scanner's own mount: nothing but the scanner itself lies within mount_radius_m of its
//    origin, and those returns move with the scanner, pulling every match towards no motion;
//  - returns beyond max_range_m: no scanner a robot carries measures that far; a point at
//    1e30 m is a broken driver or a hostile client, and one such point spreads the map's bounds
//    over the world (issue 16);
//  - a saturation shell: beams that saw nothing report the sensor's largest range (32.76 m on
//    the 3DTK SICK scans, ~1500 of 81k points), a sphere of phantom points at one range. A
//    real scene's ranges spread out; a share of at least min_saturated_share of the points
//    within saturation_band_m of the farthest range is taken for a shell and dropped.
// Ranges are measured from `sensor`, the laser's centre in the scan frame: the origin for 3DTK
// files, the mount height above it in the robot frame our scans and the MLS map use
// (PipelineConfig::sensor_height_m; measured from the origin there, the ground under the robot,
// swept densely by the fan's nadir, would be taken for the mount).
struct ReturnFilterConfig {
  Eigen::Vector3f sensor = Eigen::Vector3f::Zero();
  double mount_radius_m = 0.3;
  // Well beyond the long-range terrestrial scanners a rescue robot carries (SICK LMS 80 m, the
  // 3DTK data 33 m); coordinates stay exact to a millimetre in float there.
  double max_range_m = 1000.0;
  double saturation_band_m = 0.05;
  double min_saturated_share = 0.005;
  std::size_t min_saturated_points = 50;
};

struct DroppedReturns {
  std::size_t non_finite = 0;
  std::size_t mount = 0;
  std::size_t saturated = 0;
  std::size_t out_of_range = 0;
  std::size_t total() const { return non_finite + mount + saturated + out_of_range; }
};

// Drops those returns from `cloud` (colours kept in step) and says how many of each.
DroppedReturns drop_bad_returns(PointCloud& cloud, const ReturnFilterConfig& config = {});

// Of `candidates` (where the laser may sit in the scan frame), the one a saturation shell is
// centred on, if any shows one; otherwise the first. A shell is a sphere about the laser, so
// it tells data recorded about the laser (3DTK files) from data in the robot frame.
Eigen::Vector3f locate_sensor(const PointCloud& cloud,
                              const std::vector<Eigen::Vector3f>& candidates,
                              const ReturnFilterConfig& config = {});

}  // namespace scanplan
