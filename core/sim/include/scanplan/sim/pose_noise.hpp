#pragma once

namespace scanplan {

// Noise of the pose the robot reports (GPS/odometry); roll and pitch are measured exactly.
struct PoseNoise {
  double xy_sigma_m = 1.0;
  double z_sigma_m = 0.3;
  double yaw_sigma_deg = 5.0;
};

}  // namespace scanplan
