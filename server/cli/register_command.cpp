#include "register_command.hpp"

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/scan_returns.hpp"
#include "scanplan/io/scan_file.hpp"
#include "scanplan/registration/registration.hpp"
#include "scanplan/registration_pcl/pcl_registration.hpp"

namespace scanplan::cli {
namespace {

struct RegisterArgs {
  std::string target;
  std::string source;
  std::vector<double> init;  // x, y, z, yaw_deg; empty: identity
  std::string method = "ndt-icp";
  int dof = 4;
  double min_range = 0;  // points nearer the scanner than this are dropped (its own mount)
  double max_range = 0;  // and farther than this (saturated beams); 0: no limit
};

struct ReadScan {
  PointCloud cloud;
  DroppedReturns dropped;  // NaNs, the mount, a saturation shell (drop_bad_returns)
};

ReadScan read_scan(const std::string& file, const char* role, const RegisterArgs& a) {
  PointCloud cloud = read_point_cloud(file);  // ScanFileError names the file and what is wrong
  const DroppedReturns dropped = drop_bad_returns(cloud);
  if (a.min_range > 0 || a.max_range > 0) {
    PointCloud kept;
    for (const auto& p : cloud.points) {
      const double r = p.norm();
      if (r >= a.min_range && (a.max_range <= 0 || r <= a.max_range)) kept.points.push_back(p);
    }
    cloud = std::move(kept);
  }
  if (cloud.empty()) {
    throw std::runtime_error(
        "the " + std::string(role) + " scan " + file + " holds no points" +
        (a.min_range > 0 || a.max_range > 0 ? " within --min-range/--max-range" : std::string()) +
        ": nothing to match");
  }
  return {std::move(cloud), dropped};
}

nlohmann::ordered_json dropped_json(const DroppedReturns& d) {
  return {{"non_finite", d.non_finite},
          {"out_of_range", d.out_of_range},
          {"mount", d.mount},
          {"saturated", d.saturated}};
}

void run_register(const RegisterArgs& a) {
  const std::optional<AnyMethod> method = parse_any_method(a.method);
  if (!method) {
    throw std::runtime_error(
        "--method " + a.method +
        ": expected ndt-icp, ndt, icp, gicp, search-gicp, pcl-ndt, pcl-icp or pcl-gicp");
  }
  const ReadScan target = read_scan(a.target, "target", a);
  const ReadScan source = read_scan(a.source, "source", a);
  Pose init;
  if (!a.init.empty()) {
    init.x = a.init[0];
    init.y = a.init[1];
    init.z = a.init[2];
    init.yaw = deg2rad(a.init[3]);
  }
  RegistrationConfig config;
  config.dof = a.dof == 6 ? Dof::k6 : Dof::k4;
  const RegistrationResult r =
      register_any(target.cloud, source.cloud, init.isometry(), *method, config);

  const Pose p = Pose::from_isometry(r.transform);
  // ordered_json keeps the keys in DESIGN.md's order, which reads better than sorted.
  nlohmann::ordered_json transform = nlohmann::ordered_json::array();
  for (int row = 0; row < 4; ++row) {
    nlohmann::ordered_json values = nlohmann::ordered_json::array();
    for (int col = 0; col < 4; ++col) values.push_back(r.transform.matrix()(row, col));
    transform.push_back(values);
  }
  const nlohmann::ordered_json out = {
      {"method", r.method},
      {"transform", transform},
      {"x", p.x},
      {"y", p.y},
      {"z", p.z},
      {"roll_deg", rad2deg(p.roll)},
      {"pitch_deg", rad2deg(p.pitch)},
      {"yaw_deg", rad2deg(p.yaw)},
      {"score", r.score},
      {"rmse", r.rmse},
      {"iterations", r.iterations},
      {"time_ms", r.time_ms},
      {"converged", r.converged},
      {"dropped",
       {{"target", dropped_json(target.dropped)}, {"source", dropped_json(source.dropped)}}}};
  // Not converged is an answer, not an error: the JSON says so and stderr says why.
  if (!r.message.empty()) std::cerr << "scanplan register: " << r.message << "\n";
  std::cout << out.dump() << std::endl;
}

}  // namespace

void add_register_command(CLI::App& app) {
  auto args = std::make_shared<RegisterArgs>();
  CLI::App* cmd = app.add_subcommand(
      "register", "match a source scan to a target scan (PLY, PCD or 3DTK .3d); JSON on stdout");
  cmd->add_option("--target", args->target, "the scan matched against")->required();
  cmd->add_option("--source", args->source, "the scan moved onto the target")->required();
  cmd->add_option("--init", args->init,
                  "initial guess of the transform source -> target: x,y,z,yaw_deg (default 0)")
      ->delimiter(',')
      ->expected(4);
  cmd->add_option("--method", args->method,
                  "ndt-icp | ndt | icp | gicp | search-gicp | pcl-ndt | pcl-icp | pcl-gicp")
      ->capture_default_str();
  cmd->add_option("--dof", args->dof,
                  "4: x, y, z, yaw (roll and pitch kept from --init); 6: all six")
      ->check(CLI::IsMember({4, 6}))
      ->capture_default_str();
  cmd->add_option("--min-range", args->min_range,
                  "drop points nearer the scanner than this, in metres (points within 0.3 m, "
                  "the scanner's own mount, NaNs and a saturation shell are always dropped)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-range", args->max_range,
                  "drop points farther than this, in metres (0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args] { run_register(*args); });
}

}  // namespace scanplan::cli
