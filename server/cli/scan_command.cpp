#include "scan_command.hpp"

#include <chrono>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "operator_client.hpp"
#include "operator_options.hpp"
#include "scanplan/io/ply_io.hpp"
#include "scanplan/mapping/colorizer.hpp"
#include "scanplan/sim/simulated_shot.hpp"

namespace scanplan::cli {
namespace {

struct ScanArgs {
  std::string world;
  std::vector<double> at;
  std::string out;
  std::string image;
  std::uint64_t seed = 1;
};

void run_scan(const ScanArgs& a) {
  const auto started = std::chrono::steady_clock::now();
  const World world = load_world(a.world);
  Pose pose;
  pose.x = a.at[0];
  pose.y = a.at[1];
  pose.z = a.at[2];
  pose.yaw = deg2rad(a.at[3]);
  if (!world.in_target_region(pose.x, pose.y)) {
    throw std::runtime_error("--at " + std::to_string(pose.x) + "," + std::to_string(pose.y) +
                             " lies outside the world's target region");
  }
  const RayCaster caster(world);
  auto shot = simulate_shot(caster, world.scanner, pose, a.seed, [](double f) {
    std::cerr << "\rscanning " << static_cast<int>(f * 100) << "%" << std::flush;
    return true;
  });
  std::cerr << "\n";
  // The same colourisation the server applies: from the panorama, not the world's colours.
  const ColorizeStats stats = colorize(shot->cloud, shot->panorama, shot->camera);
  char pose_comment[160];
  std::snprintf(pose_comment, sizeof pose_comment, "scanplan true_pose %.6f %.6f %.6f %.6f", pose.x,
                pose.y, pose.z, a.at[3]);
  write_ply(
      a.out, shot->cloud,
      {pose_comment, "scanplan world " + world.name, "scanplan seed " + std::to_string(a.seed),
       "scanplan frame robot (origin on the ground under the scanner, x forward, z up)"});
  if (!a.image.empty() && !cv::imwrite(a.image, shot->panorama)) {
    throw std::runtime_error("cannot write the panorama to " + a.image);
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  const nlohmann::json out = {
      {"file", a.out},
      {"points", shot->cloud.size()},
      {"colored", stats.colored},
      {"world", world.name},
      {"seed", a.seed},
      {"true_pose", {{"x", pose.x}, {"y", pose.y}, {"z", pose.z}, {"yaw_deg", a.at[3]}}},
      {"image", a.image.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.image)},
      {"time_ms", ms}};
  std::cout << out.dump() << std::endl;
}

// The terminal operator's "scan here" (POST /api/v1/scan): every robot, or one.
void request_scan(const OperatorOptions& o, const std::string& robot) {
  const OperatorClient client(o);
  const std::string answer =
      client.post("/api/v1/scan" + (robot.empty() ? std::string() : "?robot=" + robot),
                  nlohmann::json(), "ask for a scan");
  const nlohmann::json j = nlohmann::json::parse(answer, nullptr, false);
  if (o.json) {
    std::cout << j.dump() << std::endl;
    return;
  }
  const std::string who = j.is_object() ? j.value("robot", std::string("*")) : "*";
  std::cout << "scan requested from " << (who == "*" ? std::string("every robot") : who)
            << " (command " << (j.is_object() ? j.value("command_id", 0u) : 0u)
            << "); follow it with scanplan watch" << std::endl;
}

}  // namespace

void add_scan_command(CLI::App& app) {
  auto args = std::make_shared<ScanArgs>();
  auto op = std::make_shared<OperatorOptions>();
  auto robot = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "scan",
      "with --world: one simulated scan of a world, written as PLY; without: the terminal "
      "operator asks the robots of a running server to scan where they stand");
  cmd->add_option("--world", args->world, "world file (JSON): simulate a scan offline")
      ->check(CLI::ExistingFile);
  cmd->add_option("--at", args->at, "with --world: where the robot stands, x,y,z,yaw_deg")
      ->delimiter(',')
      ->expected(4);
  cmd->add_option("--out", args->out, "with --world: output PLY (points in the robot frame)");
  cmd->add_option("--seed", args->seed, "with --world: noise seed")->capture_default_str();
  cmd->add_option("--image", args->image,
                  "with --world: also write the camera's panorama (JPEG or PNG)");
  cmd->add_option("--robot", *robot, "without --world: only this robot scans (default: every one)");
  add_operator_options(cmd, *op, "without --world: print the server's answer");
  cmd->callback([args, op, robot] {
    if (args->world.empty()) {
      run_operator_command("scan", [&] { request_scan(*op, *robot); });
      return;
    }
    if (args->at.size() != 4) throw CLI::RequiredError("--at (with --world)");
    if (args->out.empty()) throw CLI::RequiredError("--out (with --world)");
    run_scan(*args);
  });
}

}  // namespace scanplan::cli
