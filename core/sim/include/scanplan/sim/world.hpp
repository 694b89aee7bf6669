#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/pose_noise.hpp"
#include "scanplan/geometry/scanner_model.hpp"
#include "scanplan/geometry/target_region.hpp"
#include "scanplan/sim/height_grid.hpp"

namespace scanplan {

// A box standing in the world, turned by `yaw` about its own vertical centre line.
struct WorldBox {
  Eigen::Vector3d min, max;
  double yaw = 0;  // radians
  Rgb color{160, 160, 160};
};

// An upright cylinder with flat caps: lamp posts, tanks, bollards.
struct WorldCylinder {
  Eigen::Vector2d center{0, 0};
  double z_min = 0, z_max = 0;
  double radius_m = 0;
  Rgb color{150, 150, 150};
};

// An axis-aligned ellipsoid: bushes, boulders.
struct WorldEllipsoid {
  Eigen::Vector3d center{0, 0, 0};
  Eigen::Vector3d radii{0, 0, 0};
  Rgb color{70, 110, 50};
};

// A tree the robot can drive under: a cylindrical trunk with an ellipsoidal canopy resting on
// its top, so the canopy's lowest point is base.z + trunk_height_m.
struct WorldTree {
  Eigen::Vector3d base{0, 0, 0};
  double trunk_radius_m = 0;
  double trunk_height_m = 0;
  Eigen::Vector3d canopy_radii{0, 0, 0};
  Rgb color{60, 110, 45};  // the canopy
  Rgb trunk_color{95, 70, 50};

  Eigen::Vector3d canopy_center() const {
    return base + Eigen::Vector3d(0, 0, trunk_height_m + canopy_radii.z());
  }
};

// A wedge over the footprint min.xy–max.xy: its top rises linearly from min.z to max.z along
// `rise_axis` (towards +x or +y), with vertical walls down to a flat bottom at min.z.
struct WorldRamp {
  Eigen::Vector3d min{0, 0, 0}, max{0, 0, 0};
  int rise_axis = 0;  // 0: x, 1: y
  Rgb color{150, 150, 150};

  double top_z(double x, double y) const;  // the top's height over (x, y), clamped to the footprint
};

// The simulated world of a world file (format: DESIGN.md "World file"). Metres, z up.
struct World {
  std::string name;
  // The target region's bounding box; when the file gives a polygon, `bounds_polygon` holds
  // it (counter-clockwise or clockwise) and is what in_target_region tests.
  Eigen::Vector2d bounds_min{0, 0}, bounds_max{0, 0};
  std::vector<Eigen::Vector2d> bounds_polygon;
  double ground_z = 0;  // the flat ground, used when there is no grid
  std::optional<HeightGrid> ground_grid;
  Rgb ground_color{110, 120, 90};
  std::vector<WorldBox> boxes;
  std::vector<WorldCylinder> cylinders;
  std::vector<WorldEllipsoid> ellipsoids;
  std::vector<WorldTree> trees;
  std::vector<WorldRamp> ramps;
  Pose start;  // z is the ground height under the start
  ScannerConfig scanner;
  // Drifting odometry unless the world file says otherwise (DESIGN.md "Scanner model").
  PoseNoise pose_noise{.model = OdometryModel::kDrift};

  // The height of the ground surface alone (objects standing on it are not counted).
  double ground_height(double x, double y) const;
  // Whether (x, y) lies in the target region; points on its border count as inside.
  bool in_target_region(double x, double y) const;
  // The target region as the planner and the segmentation take it.
  TargetRegion target_region() const;
};

// Thrown for a world file that cannot be used; the message names the file, object and field.
class WorldError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

World parse_world(const std::string& json_text, const std::string& source_name);
World load_world(const std::filesystem::path& file);

}  // namespace scanplan
