#include "simulated_robot.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "scanplan/io/image_codec.hpp"
#include "scanplan/sim/simulated_shot.hpp"

namespace scanplan::bridge {

SimulatedRobot::SimulatedRobot(World world, dds::Participant& participant, BridgeOptions options)
    : world_(std::move(world)),
      caster_(world_),
      traversability_(world_, caster_),
      options_(std::move(options)),
      publisher_(participant, options_.robot_id),
      commands_(participant, options_.robot_id),
      true_pose_(traversability_.standing_pose(world_.start.x, world_.start.y, world_.start.z,
                                               world_.start.yaw)),
      odometry_(world_.pose_noise, true_pose_, options_.seed) {}

bool SimulatedRobot::pass_time(double simulated_s, const std::atomic<bool>& stop,
                               const std::function<void(double share)>& tick) const {
  if (options_.time_scale <= 0) return !stop;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const auto span = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(simulated_s / options_.time_scale));
  const Clock::time_point until = start + span;
  Clock::time_point next_tick = start + kDriveReport;
  // Short naps so that a stop request is noticed mid-drive.
  while (!stop && Clock::now() < until) {
    std::this_thread::sleep_until(std::min(until, Clock::now() + std::chrono::milliseconds(50)));
    if (tick && Clock::now() >= next_tick && Clock::now() < until) {
      tick(std::chrono::duration<double>(Clock::now() - start) / span);
      next_tick += kDriveReport;
    }
  }
  return !stop;
}

void SimulatedRobot::run(const std::atomic<bool>& stop) {
  spdlog::info("robot '{}' ready in world '{}' at ({:.2f}, {:.2f}), waiting for commands",
               options_.robot_id, world_.name, true_pose_.x, true_pose_.y);
  auto last_status = std::chrono::steady_clock::time_point{};
  while (!stop) {
    // A periodic idle status lets a server that started later learn where the robot is.
    if (std::chrono::steady_clock::now() - last_status > std::chrono::seconds(1)) {
      publisher_.status(0, "idle", odometry_.reported());
      last_status = std::chrono::steady_clock::now();
    }
    for (const Command& c : commands_.wait(std::chrono::milliseconds(200))) {
      if (stop) break;
      if (const auto* s = std::get_if<ScanRequest>(&c)) scan(s->command_id, stop);
      if (const auto* m = std::get_if<MoveRequest>(&c)) move(*m, stop);
      last_status = std::chrono::steady_clock::now();
    }
  }
  publisher_.goodbye(odometry_.reported());
}

void SimulatedRobot::scan(std::uint32_t command_id, const std::atomic<bool>& stop) {
  spdlog::info("scan command {}: scanning", command_id);
  publisher_.status(command_id, "scanning", odometry_.reported());
  publisher_.progress(command_id, "scanning", 0.0f);
  const ScannerConfig& cfg = world_.scanner;
  const auto started = std::chrono::steady_clock::now();
  float last_reported = 0.0f;
  // The rotation stage takes scan_duration_s of simulated time; pacing the progress callback
  // against the wall clock makes the operator's progress bar move as the real scanner's would.
  const auto progress = [&](double fraction) {
    if (options_.time_scale > 0) {
      std::this_thread::sleep_until(
          started +
          std::chrono::duration<double>(cfg.scan_duration_s * fraction / options_.time_scale));
    }
    if (fraction - last_reported >= 0.01 || fraction >= 1.0) {
      last_reported = static_cast<float>(fraction);
      publisher_.progress(command_id, "scanning", last_reported);
    }
    return !stop.load();
  };
  const std::uint64_t seed = options_.seed * 1000003u + scans_taken_++;
  auto simulated = simulate_shot(caster_, cfg, true_pose_, seed, progress);
  if (!simulated) {
    publisher_.progress(command_id, "failed", last_reported, "the scanner was shut down mid-scan");
    return;
  }
  const PointCloud& cloud = simulated->cloud;
  CameraShot shot{encode_jpeg(simulated->panorama, cfg.camera_jpeg_quality), simulated->camera};
  publisher_.scan(cloud, odometry_.reported(), shot);
  publisher_.progress(command_id, "done", 1.0f, std::to_string(cloud.size()) + " points");
  publisher_.status(command_id, "idle", odometry_.reported());
  spdlog::info("scan command {}: published {} points and a {}-byte panorama", command_id,
               cloud.size(), shot.jpeg.size());
}

void SimulatedRobot::move(const MoveRequest& goal, const std::atomic<bool>& stop) {
  const auto refuse = [&](const std::string& why) {
    spdlog::warn("move command {} to ({:.2f}, {:.2f}) refused: {}", goal.command_id, goal.x, goal.y,
                 why);
    publisher_.status(goal.command_id, "refused", odometry_.reported(), why);
  };
  if (!std::isfinite(goal.x) || !std::isfinite(goal.y) || !std::isfinite(goal.yaw_deg)) {
    return refuse("the goal is not a finite position");
  }
  const auto goal_cell = traversability_.cell_of(goal.x, goal.y);
  if (!goal_cell) return refuse("the goal lies outside the target region");
  const auto reach = traversability_.reach_from(true_pose_.x, true_pose_.y, true_pose_.z);
  if (!reach.reachable(*goal_cell)) {
    return refuse(traversability_.surfaces(*goal_cell).empty()
                      ? "the goal is inside an obstacle or under too low a ceiling"
                      : "no drivable path leads to the goal (steps over 0.15 m or obstacles)");
  }
  const double distance = reach.distance_m[*goal_cell];
  spdlog::info("move command {}: driving {:.1f} m to ({:.2f}, {:.2f})", goal.command_id, distance,
               goal.x, goal.y);
  publisher_.status(goal.command_id, "moving", odometry_.reported());
  // On the way it reports where it is: between where its odometry had it and the goal, by the
  // share of the drive done (the path's bends are not followed; what matters to the operator
  // is that the distance to go shrinks).
  const Pose from = odometry_.reported();
  const auto report = [&](double share) {
    Pose at = from;
    at.x += share * (goal.x - from.x);
    at.y += share * (goal.y - from.y);
    publisher_.status(goal.command_id, "moving", at);
  };
  if (!pass_time(distance / options_.speed_mps, stop, report)) return;
  true_pose_ =
      traversability_.standing_pose(goal.x, goal.y, reach.z[*goal_cell], deg2rad(goal.yaw_deg));
  odometry_.moved(true_pose_, distance);
  publisher_.status(goal.command_id, "arrived", odometry_.reported(),
                    "drove " + std::to_string(static_cast<int>(std::lround(distance))) + " m");
}

}  // namespace scanplan::bridge
