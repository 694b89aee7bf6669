#pragma once

#include <cstdint>
#include <random>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/pose_noise.hpp"

namespace scanplan {

// The simulated robot's pose sensors: what it reports where it stands, by PoseNoise's model.
// One per robot, fed every move it makes in order; the same seed and moves give the same reports.
class SimulatedOdometry {
 public:
  // The robot stands at `truth`. Drifting odometry starts from it exactly (its frame is where
  // the mission began); absolute noise disturbs it already.
  SimulatedOdometry(const PoseNoise& noise, const Pose& truth, std::uint64_t seed);

  // The robot drove `path_m` (over the ground, ≥ the straight line) and now stands at `truth`.
  void moved(const Pose& truth, double path_m);
  // What the robot reports now: x, y, z and yaw as the model disturbs them, roll and pitch true.
  const Pose& reported() const { return reported_; }

 private:
  Pose absolute(const Pose& truth);

  PoseNoise noise_;
  std::mt19937_64 rng_;
  Pose truth_, reported_;
};

}  // namespace scanplan
