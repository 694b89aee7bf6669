#pragma once

#include <Eigen/Core>
#include <optional>

#include "scanplan/geometry/scanner_model.hpp"

namespace scanplan {

// The scanner's colour camera as one equirectangular panorama, its axes those of the robot
// frame: column u runs from behind-right (u = 0) through straight ahead (u = W/2) to
// behind-left, row v from straight up (v = 0) to straight down (v = H). The real device turns
// its CCD camera with the rotation stage (paper Fig. 1); a stitched panorama is what it yields.
struct PanoramaCamera {
  int width_px = 1024;
  int height_px = 512;
  // Optical centre in the robot frame; above the laser's centre, so parallax makes occlusion
  // between laser and camera possible and colourisation has to check for it.
  Eigen::Vector3d center_robot{0.0, 0.0, 1.15};

  // The camera the scanner model carries.
  static PanoramaCamera for_scanner(const ScannerConfig& scanner);

  // Continuous pixel coordinates of a direction in the robot frame (need not be unit length).
  Eigen::Vector2d project_direction(const Eigen::Vector3d& dir) const;
  // Unit direction in the robot frame through continuous pixel coordinates (u, v).
  Eigen::Vector3d pixel_direction(double u, double v) const;
  // Pixel of a point in the robot frame, or nothing for the optical centre itself.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3f& point_robot) const;
};

}  // namespace scanplan
