#include "scanplan/geometry/panorama_camera.hpp"

#include <cmath>

namespace scanplan {

PanoramaCamera PanoramaCamera::for_scanner(const ScannerConfig& scanner) {
  PanoramaCamera c;
  c.width_px = scanner.camera_width_px;
  c.height_px = scanner.camera_width_px / 2;
  c.center_robot = {0.0, 0.0, scanner.mount_height_m + scanner.camera_above_laser_m};
  return c;
}

Eigen::Vector2d PanoramaCamera::project_direction(const Eigen::Vector3d& dir) const {
  const double az = std::atan2(dir.y(), dir.x());
  const double el = std::atan2(dir.z(), std::hypot(dir.x(), dir.y()));
  return {width_px * (0.5 - az / (2 * M_PI)), height_px * (0.5 - el / M_PI)};
}

Eigen::Vector3d PanoramaCamera::pixel_direction(double u, double v) const {
  const double az = (0.5 - u / width_px) * 2 * M_PI;
  const double el = (0.5 - v / height_px) * M_PI;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

std::optional<Eigen::Vector2d> PanoramaCamera::project(const Eigen::Vector3f& point_robot) const {
  const Eigen::Vector3d d = point_robot.cast<double>() - center_robot;
  if (d.squaredNorm() < 1e-12) return std::nullopt;
  return project_direction(d);
}

}  // namespace scanplan
