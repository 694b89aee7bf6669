#pragma once

#include <optional>
#include <string_view>

namespace scanplan {

// How a robot's reported pose goes wrong (DESIGN.md "Scanner model"); the simulator draws its
// errors by it and the pose graph weighs the robot's account of its moves by it.
enum class OdometryModel {
  // Integrated odometry: each move adds an error that grows with the distance driven, and the
  // error of a heading carries into every later position. What a robot without GNSS reports.
  kDrift,
  // The true pose plus independent noise at every stop, as from a GNSS fix (kinder: the error
  // does not grow).
  kAbsolute,
};

// "drift", "absolute"; nullopt for anything else.
std::optional<OdometryModel> parse_odometry_model(std::string_view name);
std::string_view odometry_model_name(OdometryModel model);

// The pose sensors' error; roll and pitch come from the inclination sensor and are exact.
struct PoseNoise {
  // kAbsolute: σ of each reported pose.
  double xy_sigma_m = 1.0;
  double z_sigma_m = 0.3;
  double yaw_sigma_deg = 5.0;
  // Left last so that the brace-initialised absolute figures above keep their meaning.
  OdometryModel model = OdometryModel::kAbsolute;
  // kDrift, per move of d metres driven (issue 17): σ of the error along and across the move
  // = xy_drift_fraction·d, of the heading change = yaw_drift_deg_per_10m·d/10, of the height
  // change = z_drift_fraction·d (the height follows the ground the wheels roll on, with the
  // slope measured by the inclination sensor, so it drifts far less than x-y).
  double xy_drift_fraction = 0.02;
  double yaw_drift_deg_per_10m = 0.3;
  double z_drift_fraction = 0.002;
};

}  // namespace scanplan
