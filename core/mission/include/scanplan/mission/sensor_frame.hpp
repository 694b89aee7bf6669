#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/pose_noise.hpp"
#include "scanplan/mission/move_uncertainty.hpp"

namespace scanplan {

// Where the robot's pose-sensor frame lies in the map frame (ROS's map → odom). The first scan
// defines the map frame at the pose it was reported at, errors included: 5° of yaw error there
// puts a scan reported correctly 100 m away 8.7 m off in the map, beyond any matcher's reach,
// and an unmatched scan placed at its reported pose lands just as far off. Every scan a believed
// match placed measures the offset once more (reported in the sensor frame, placed in the map
// frame), so the estimate tightens as the mission goes on and a new scan's reported pose,
// carried into the map frame, is wrong by little more than one scan's sensor error.
//
// The estimate: the x-y-yaw transform (and z shift) minimising
//   Σ_i |placed_i − R(θ)·reported_i − t|² / σ_xy² + Σ_i (placed_yaw_i − reported_yaw_i − θ)² /
//   σ_yaw²
// over the anchored scans: positions far apart fix θ better than the yaw readings do.
class SensorFrame {
 public:
  explicit SensorFrame(PoseNoise noise = {}) : noise_(noise) {}
  // Fitted once to every scan whose map pose is known (add() refits with each).
  SensorFrame(PoseNoise noise, std::vector<Pose> reported, std::vector<Pose> placed);

  // One scan whose map pose is known: the first, or one placed by a believed match.
  void add(const Pose& reported, const Pose& placed);
  // `reported` carried into the map frame (roll and pitch as they are: the inclination sensor
  // measures them against gravity, which both frames share). `reported` itself before any add.
  Pose to_map(const Pose& reported) const;
  // How far off to_map(reported) may be: the fix's own error and the frame's, which the anchored
  // scans measure the better the more of them there are and the farther apart they lie (with
  // one, a scan 100 m from it is off by that one's 5° of heading: 8.7 m). The fix's own error
  // alone before any add.
  MoveUncertainty spread(const Pose& reported) const;

 private:
  void refit();
  Eigen::Vector2d turned(const Pose& reported) const;

  PoseNoise noise_;
  std::vector<Pose> reported_, placed_;
  double yaw_ = 0, tx_ = 0, ty_ = 0, tz_ = 0;             // map_from_sensor
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();  // of (yaw_, tx_, ty_)
};

}  // namespace scanplan
