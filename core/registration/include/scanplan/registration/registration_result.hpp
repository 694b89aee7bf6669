#pragma once

#include <Eigen/Geometry>
#include <string>

namespace scanplan {

// Which parameters scan matching may change. The scanner carries an inclination sensor, so
// roll and pitch are measured and only x, y, z and yaw are adjusted (paper §4.3); k6 frees all
// six for data without such a sensor.
//
// In 4 DOF the rotation turns about the target frame's z axis only: the roll and pitch of the
// initial transform (Rz·Ry·Rx, as in Pose) are kept exactly. That is right when the target's z
// is vertical — a levelled scan or the map frame.
enum class Dof { k4, k6 };

// The outcome of one scan match, whatever the method.
struct RegistrationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // maps source into target
  // Paper Eq. 2: the sum over source points of the squared distance to the closest target point
  // after `transform`. Every method is scored by the same code on the same (downsampled) points,
  // each distance truncated at RegistrationConfig::score_max_distance_m so that parts seen by
  // one scan only add a constant instead of dominating the sum.
  double score = 0;
  double rmse = 0;          // over the source points whose closest target point is an inlier
  double inlier_ratio = 0;  // share of source points with a target point within the inlier distance
  // The sanity check's AlignmentQuality::weakest_constraint; 0 when the solver did not settle.
  double weakest_constraint = 0;
  // The weakest constraint was below the check's, but restarts from around the result all came
  // back to it (RegistrationConfig::restart_check), so it was believed.
  bool held_on_restart = false;
  // AlignmentQuality::information at the result (x, y, z, yaw about the source's origin, in
  // the target frame); zero when the solver did not settle.
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  int iterations = 0;  // summed over all stages (cell sizes, NDT then ICP)
  double time_ms = 0;  // the alignment itself: downsampling and scoring excluded
  bool converged =
      false;  // the solver stopped on its tolerances AND the result passed the sanity check
  // The solver used up its iterations without settling: `transform` is where it stopped. Along
  // a corridor it slides a few millimetres a step for ever, so the check is still made there
  // for the message (a corridor says why better than "did not settle").
  bool ran_out = false;
  std::string method;   // "ndt-icp", "ndt", "icp", "pcl-ndt", "pcl-icp", "pcl-gicp"
  std::string message;  // why it did not converge, or a note (e.g. "PCL solves 6 DOF")
};

}  // namespace scanplan
