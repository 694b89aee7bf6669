#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanplan/core/point_cloud.hpp"
#include "scanplan/core/pose.hpp"
#include "scanplan/core/scanner_model.hpp"

namespace scanplan {

// A box standing in the world, turned by `yaw` about its own vertical centre line.
struct WorldBox {
  Eigen::Vector3d min, max;
  double yaw = 0;  // radians
  Rgb color{160, 160, 160};
};

// The simulated world of a world file (format: DESIGN.md "World file"). Metres, z up.
struct World {
  std::string name;
  Eigen::Vector2d bounds_min{0, 0}, bounds_max{0, 0};  // the target region
  double ground_z = 0;
  Rgb ground_color{110, 120, 90};
  std::vector<WorldBox> boxes;
  Pose start;  // z is the ground height under the start
  ScannerConfig scanner;
  PoseNoise pose_noise;
};

// Thrown for a world file that cannot be used; the message names the file, object and field.
class WorldError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

World parse_world(const std::string& json_text, const std::string& source_name);
World load_world(const std::filesystem::path& file);

}  // namespace scanplan
