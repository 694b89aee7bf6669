#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "command_reader.hpp"
#include "scanner_publisher.hpp"
#include "scanplan/sim/ray_caster.hpp"
#include "scanplan/sim/simulated_odometry.hpp"
#include "scanplan/sim/world.hpp"
#include "scanplan/sim/world_traversability.hpp"

namespace scanplan::bridge {

struct BridgeOptions {
  std::string robot_id = "robot1";
  double time_scale = 1.0;  // simulated seconds per wall-clock second; 0 runs without pauses
  std::uint64_t seed = 1;
  double speed_mps = 0.5;  // driving speed over rough ground
};

// Stands for the scanner robot on DDS in a simulated world: scans where it truly stands
// (publishing the pose it would report: SimulatedOdometry, drifting or absolute), and drives to
// goals it can reach.
// How often a driving robot reports where it is: the operator sees the distance to go shrink.
inline constexpr std::chrono::milliseconds kDriveReport{500};

class SimulatedRobot {
 public:
  SimulatedRobot(World world, dds::Participant& participant, BridgeOptions options);
  // Serves commands until `stop` becomes true.
  void run(const std::atomic<bool>& stop);

 private:
  void scan(std::uint32_t command_id, const std::atomic<bool>& stop);
  void move(const MoveRequest& goal, const std::atomic<bool>& stop);
  // Sleeps for `simulated_s` of simulated time; false when stopped meanwhile. `tick` is called
  // with the share of the time passed about every kDriveReport of real time.
  bool pass_time(double simulated_s, const std::atomic<bool>& stop,
                 const std::function<void(double share)>& tick = {}) const;

  World world_;
  RayCaster caster_;
  WorldTraversability traversability_;
  BridgeOptions options_;
  ScannerPublisher publisher_;
  CommandReader commands_;
  Pose true_pose_;
  SimulatedOdometry odometry_;
  std::uint64_t scans_taken_ = 0;
};

}  // namespace scanplan::bridge
