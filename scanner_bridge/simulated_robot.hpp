#pragma once

#include <atomic>
#include <cstdint>
#include <random>
#include <string>

#include "scanplan/core/ray_caster.hpp"
#include "scanplan/core/world.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::bridge {

struct BridgeOptions {
  std::string robot_id = "robot1";
  double time_scale = 1.0;  // simulated seconds per wall-clock second
  std::uint64_t seed = 1;
};

// Stands for the scanner robot on DDS: answers each scan command with a simulated scan at the
// robot's true pose, published with the pose the robot would report (true pose + noise).
class SimulatedRobot {
 public:
  SimulatedRobot(World world, dds::Participant& participant, BridgeOptions options);
  // Serves commands until `stop` becomes true.
  void run(const std::atomic<bool>& stop);

 private:
  void scan(std::uint32_t command_id, const std::atomic<bool>& stop);
  void publish_progress(std::uint32_t command_id, const std::string& state, float fraction,
                        const std::string& message);

  World world_;
  RayCaster caster_;
  dds::Participant& participant_;
  BridgeOptions options_;
  Pose true_pose_;
  std::mt19937_64 pose_rng_;
  std::uint64_t scans_taken_ = 0;
  dds_entity_t scan_cmd_reader_, points_writer_, pose_writer_, progress_writer_;
};

}  // namespace scanplan::bridge
