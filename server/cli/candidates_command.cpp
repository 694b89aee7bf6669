#include "candidates_command.hpp"

#include <algorithm>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "ascii_top_view.hpp"
#include "candidate_table.hpp"
#include "operator_client.hpp"
#include "region_raster.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

struct CandidatesArgs {
  OperatorOptions o;
  int width = 60, height = 20;
  bool no_map = false;
  bool whole = false;
};

// The top view from what the API gives: the target region (params), the regions layer, the
// scan points as placed (scans), the robots' reported positions (session) and the candidates.
std::vector<std::string> top_view(const OperatorClient& client, const json& answer,
                                  const TopViewSize& size, bool whole) {
  const json params = client.get_json("/api/v1/params", "read the parameters");
  const json& target = params.at("target");
  if (!target.is_array() || target.empty()) {
    return {"(no top view: the server has no target region yet)"};
  }
  TopViewInput in;
  in.min_x = in.min_y = std::numeric_limits<double>::max();
  in.max_x = in.max_y = std::numeric_limits<double>::lowest();
  for (const json& corner : target) {
    in.min_x = std::min(in.min_x, corner.at(0).get<double>());
    in.max_x = std::max(in.max_x, corner.at(0).get<double>());
    in.min_y = std::min(in.min_y, corner.at(1).get<double>());
    in.max_y = std::max(in.max_y, corner.at(1).get<double>());
  }
  std::vector<std::string> notes;
  std::optional<RegionRaster> raster;
  if (const auto png = client.get_bytes("/api/v1/layers/regions.png", "read the regions layer")) {
    try {
      raster = decode_regions_png(*png, in.min_x, in.min_y, in.max_x, in.max_y);
      in.regions = &*raster;
    } catch (const std::runtime_error& e) {
      notes.push_back(std::string("(regions not shown: ") + e.what() + ")");
    }
  }
  // Named: a range-for over a part of a temporary would outlive it (found by AddressSanitizer).
  const json scans = client.get_json("/api/v1/scans", "list the scans");
  for (const json& s : scans.at("scans")) {
    in.scan_points.push_back(
        {s.at("placed").at("x").get<double>(), s.at("placed").at("y").get<double>()});
  }
  const json session = client.get_json("/api/v1/session", "read the session");
  for (const auto& [id, r] : session.at("robots").items()) {
    in.robots.push_back({r.at("pose").at("x").get<double>(), r.at("pose").at("y").get<double>()});
  }
  // Only what the operator can still act on or is under way; the table lists the rest.
  for (const json& c : answer.at("candidates")) {
    const std::string state = c.at("state").get<std::string>();
    if (state == "proposed" || state == "moving") {
      in.candidates.push_back(
          {c.at("rank").get<int>(), c.at("x").get<double>(), c.at("y").get<double>()});
    }
  }
  if (!whole) zoom_to_known_area(in);
  std::vector<std::string> out = render_ascii_top_view(in, size);
  out.insert(out.end(), notes.begin(), notes.end());
  return out;
}

void run_candidates(const CandidatesArgs& a) {
  const OperatorClient client(a.o);
  if (a.o.json) {
    std::string body = client.get_raw("/api/v1/candidates", "list the candidates");
    while (!body.empty() && (body.back() == '\n' || body.back() == '\r')) body.pop_back();
    std::cout << body << std::endl;
    return;
  }
  const json answer = client.get_json("/api/v1/candidates", "list the candidates");
  for (const std::string& line : render_candidate_table(answer)) std::cout << line << "\n";
  if (!a.no_map && !answer.at("plan").is_null()) {
    std::cout << "\n";
    for (const std::string& line : top_view(client, answer, {a.width, a.height, 2.0}, a.whole)) {
      std::cout << line << "\n";
    }
  }
  std::cout.flush();
}

}  // namespace

void add_candidates_command(CLI::App& app) {
  auto a = std::make_shared<CandidatesArgs>();
  CLI::App* cmd = app.add_subcommand(
      "candidates", "terminal operator: the planner's next scan points, as a table and a top view");
  add_operator_options(cmd, a->o, "print the server's GET /api/v1/candidates answer as it came");
  cmd->add_option("--width", a->width, "top view: at most this many characters wide")
      ->check(CLI::Range(10, 400))
      ->capture_default_str();
  cmd->add_option("--height", a->height, "top view: at most this many lines high")
      ->check(CLI::Range(5, 200))
      ->capture_default_str();
  cmd->add_flag("--no-map", a->no_map, "the table only, without the top view");
  cmd->add_flag("--whole", a->whole,
                "top view of the whole target region (default: the part with data, scan points "
                "and candidates)");
  cmd->callback([a] { run_operator_command("candidates", [&] { run_candidates(*a); }); });
}

}  // namespace scanplan::cli
