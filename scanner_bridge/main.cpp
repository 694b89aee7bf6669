// scanplan-bridge: the scanner robot on DDS (DESIGN.md "Processes"): a simulated robot in a
// world file, or a recording played back.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <vector>

#include "replay_robot.hpp"
#include "scanplan/msgs/dds_participant.hpp"
#include "scanplan/sim/ray_caster.hpp"
#include "scanplan/sim/world_traversability.hpp"
#include "simulated_robot.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}
// Whether a robot placed at the world's start stands on ground the bridge can drive from.
bool can_stand_at_start(const scanplan::World& world) {
  const scanplan::RayCaster caster(world);
  const scanplan::WorldTraversability ground(world, caster);
  const auto cell = ground.cell_of(world.start.x, world.start.y);
  if (!cell) return false;
  const auto& surfaces = ground.surfaces(*cell);
  return std::any_of(surfaces.begin(), surfaces.end(),
                     [&](float z) { return std::abs(z - world.start.z) < 0.3; });
}
// A replayed scan "takes" 3 s instead of the scanner's 60.
constexpr double kReplayTimeScale = 20.0;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scanplan-bridge: a 3-D scanner robot on DDS (simulated or replayed)"};
  std::string world_file, replay_dir;
  std::uint32_t domain = 0;
  scanplan::bridge::BridgeOptions options;
  auto* world_opt = app.add_option("--world", world_file, "world file (JSON) to simulate");
  auto* replay_opt = app.add_option("--replay", replay_dir, "folder of recorded scans to play");
  world_opt->excludes(replay_opt);
  app.add_option("--domain", domain, "DDS domain id")->capture_default_str();
  app.add_option("--robot-id", options.robot_id, "robot id, first part of every frame_id")
      ->capture_default_str();
  auto* scale_opt =
      app.add_option("--time-scale", options.time_scale,
                     "simulated seconds per real second (a scan takes 60 s simulated; 0: no "
                     "waiting); default 1 for --world, 20 for --replay (3 s a recorded scan)")
          ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", options.seed, "seed for range and pose noise")->capture_default_str();
  std::vector<double> start;
  auto* start_opt = app.add_option("--start", start,
                                   "x,y,yaw_deg: where the simulated robot starts (default: the "
                                   "world's start; several robots need one each)")
                        ->expected(3)
                        ->delimiter(',');
  start_opt->needs(world_opt);
  std::string odometry;
  app.add_option("--odometry", odometry,
                 "drift|absolute: how the reported pose goes wrong (default: the world file's "
                 "pose_noise.model, drift when it has none)")
      ->check(CLI::IsMember({"drift", "absolute"}))
      ->needs(world_opt);
  CLI11_PARSE(app, argc, argv);
  spdlog::set_default_logger(spdlog::stderr_color_mt("bridge"));
  if (world_file.empty() == replay_dir.empty()) {
    spdlog::error("give exactly one of --world FILE or --replay DIR");
    return 2;
  }

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    scanplan::dds::Participant participant(domain);
    if (!world_file.empty()) {
      scanplan::World world = scanplan::load_world(world_file);
      if (!start.empty()) {
        world.start.x = start[0];
        world.start.y = start[1];
        world.start.z = world.ground_height(start[0], start[1]);
        world.start.yaw = scanplan::deg2rad(start[2]);
        if (!can_stand_at_start(world)) {
          spdlog::error(
              "--start {},{}: no ground a robot can stand on there in world '{}' (inside an "
              "obstacle, or outside the target region)",
              start[0], start[1], world.name);
          return 2;
        }
      }
      if (!odometry.empty()) world.pose_noise.model = *scanplan::parse_odometry_model(odometry);
      scanplan::bridge::SimulatedRobot robot(std::move(world), participant, options);
      robot.run(g_stop);
    } else {
      // A recording was taken already: waiting a minute for each scan again only keeps the
      // operator from looking at it (issue 18).
      if (scale_opt->count() == 0) options.time_scale = kReplayTimeScale;
      scanplan::bridge::ReplayOptions replay{options.robot_id, options.time_scale};
      scanplan::bridge::ReplayRobot robot(scanplan::ReplayFolder(replay_dir), participant, replay);
      robot.run(g_stop);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
