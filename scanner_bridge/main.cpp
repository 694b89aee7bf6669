// scanplan-bridge: the scanner robot on DDS (DESIGN.md "Processes").
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>

#include "scanplan/msgs/dds_participant.hpp"
#include "simulated_robot.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scanplan-bridge: a 3-D scanner robot on DDS (simulated)"};
  std::string world_file;
  std::uint32_t domain = 0;
  scanplan::bridge::BridgeOptions options;
  app.add_option("--world", world_file, "world file (JSON) to simulate")->required();
  app.add_option("--domain", domain, "DDS domain id")->capture_default_str();
  app.add_option("--robot-id", options.robot_id, "robot id, first part of every frame_id")
      ->capture_default_str();
  app.add_option("--time-scale", options.time_scale,
                 "simulated seconds per real second (a scan takes 60 s simulated)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", options.seed, "seed for range and pose noise")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  spdlog::set_default_logger(spdlog::stderr_color_mt("bridge"));

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    scanplan::World world = scanplan::load_world(world_file);
    scanplan::dds::Participant participant(domain);
    scanplan::bridge::SimulatedRobot robot(std::move(world), participant, options);
    robot.run(g_stop);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
