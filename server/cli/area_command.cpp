#include "area_command.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "operator_client.hpp"
#include "operator_error.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

struct AreaArgs {
  OperatorOptions o;
  std::string target;
  std::vector<std::string> no_go;
  bool clear_no_go = false;
  std::string by;
};

// "x,y x,y x,y" (spaces or semicolons between corners) as [[x, y], ...]; the server checks the
// polygon itself.
json corners_of(const std::string& text, const std::string& what) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ';') c = ' ';
  }
  std::istringstream in(spaced);
  json corners = json::array();
  for (std::string corner; in >> corner;) {
    double x = 0, y = 0;
    char rest = 0;
    if (std::sscanf(corner.c_str(), "%lf,%lf%c", &x, &y, &rest) != 2 || !std::isfinite(x) ||
        !std::isfinite(y)) {
      throw OperatorError(
          ExitCode::kBadRequest,
          what + ": '" + corner + "' is not a corner x,y in metres (give \"x,y x,y x,y ...\")");
    }
    corners.push_back({x, y});
  }
  if (corners.size() < 3) {
    throw OperatorError(ExitCode::kBadRequest,
                        what + " needs at least three corners \"x,y x,y x,y\", got '" + text + "'");
  }
  return corners;
}

std::string polygon_text(const json& corners) {
  std::string text;
  char buf[64];
  for (const json& c : corners) {
    std::snprintf(buf, sizeof buf, "%s(%.1f, %.1f)", text.empty() ? "" : " ", c.at(0).get<double>(),
                  c.at(1).get<double>());
    text += buf;
  }
  return text;
}

void print_area(const json& params) {
  const json& target = params.at("target");
  if (target.is_array()) {
    std::cout << "target area (" << target.size() << " corners, m): " << polygon_text(target)
              << "\n";
  } else {
    std::cout << "target area: the default, a square around the first scan (set one with "
                 "--target)\n";
  }
  const json& zones = params.at("no_go");
  if (zones.empty()) std::cout << "no-go zones: none\n";
  for (std::size_t i = 0; i < zones.size(); ++i) {
    std::cout << "no-go zone " << i + 1 << ": " << polygon_text(zones[i]) << "\n";
  }
  std::cout.flush();
}

void run_area(const AreaArgs& a) {
  const OperatorClient client(a.o);
  json change = json::object();
  if (!a.target.empty()) change["target"] = corners_of(a.target, "--target");
  if (a.clear_no_go || !a.no_go.empty()) {
    json zones = json::array();
    for (std::size_t i = 0; i < a.no_go.size(); ++i) {
      zones.push_back(corners_of(a.no_go[i], "--no-go " + std::to_string(i + 1)));
    }
    change["no_go"] = zones;
  }
  json params;
  if (change.empty()) {
    params = client.get_json("/api/v1/params", "read the mission's area");
  } else {
    if (!a.by.empty()) change["by"] = a.by;
    params =
        json::parse(client.put("/api/v1/params", change, "set the mission's area"), nullptr, false);
  }
  if (a.o.json) {
    std::cout << params.dump() << std::endl;
    return;
  }
  if (!params.is_object())
    throw OperatorError(ExitCode::kFailure, "the server's answer is not JSON");
  print_area(params);
}

}  // namespace

void add_area_command(CLI::App& app) {
  auto a = std::make_shared<AreaArgs>();
  CLI::App* cmd = app.add_subcommand(
      "area",
      "terminal operator: the target area being mapped and the no-go zones; with --target or "
      "--no-go, sets them (the planner re-plans at once)");
  cmd->add_option("--target", a->target,
                  "the target area's corners in the map frame, \"x,y x,y x,y ...\" (metres)");
  cmd->add_option("--no-go", a->no_go,
                  "a no-go zone \"x,y x,y x,y ...\"; repeat for several. Replaces the zones "
                  "there were");
  cmd->add_flag("--clear-no-go", a->clear_no_go, "remove every no-go zone");
  cmd->add_option("--by", a->by, "who sets it, for the decision log");
  add_operator_options(cmd, a->o, "print the server's parameters as JSON");
  cmd->callback([a] { run_operator_command("area", [&] { run_area(*a); }); });
}

}  // namespace scanplan::cli
