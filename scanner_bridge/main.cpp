// scanplan-bridge: the scanner robot on DDS (DESIGN.md "Processes"): a simulated robot in a
// world file, or a recording played back.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>

#include "replay_robot.hpp"
#include "scanplan/msgs/dds_participant.hpp"
#include "simulated_robot.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}
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
  app.add_option("--time-scale", options.time_scale,
                 "simulated seconds per real second (a scan takes 60 s simulated; 0: no waiting)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", options.seed, "seed for range and pose noise")->capture_default_str();
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
      scanplan::bridge::SimulatedRobot robot(scanplan::load_world(world_file), participant,
                                             options);
      robot.run(g_stop);
    } else {
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
