#pragma once

namespace scanplan {

// How far off a pose may be: σ of each x-y axis, of z and of the yaw. Carried by odometry from
// the robot's previous scan (ScanGraph), or carried into the map frame from an absolute fix
// (SensorFrame::spread).
struct MoveUncertainty {
  double xy_m = 0, z_m = 0, yaw_deg = 0;
  bool operator==(const MoveUncertainty&) const = default;
};

}  // namespace scanplan
