#include "status_report.hpp"

#include <cmath>

#include "text_format.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

// Column of labels, so the values line up on a terminal.
std::string row(const std::string& label, const std::string& value) {
  std::string s = label;
  s.resize(12, ' ');
  return s + value;
}

std::string pose_text(const json& p) {
  return "at " + position(p.at("x").get<double>(), p.at("y").get<double>()) + ", z " +
         fixed(p.at("z").get<double>(), 1) + " m, heading " +
         fixed(p.at("yaw_deg").get<double>(), 0) + " deg";
}

std::string plural(std::int64_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

double wrap_deg(double d) {
  return std::remainder(d, 360.0);
}

}  // namespace

std::vector<std::string> render_status(const std::string& server, const json& session,
                                       const json& scans) {
  std::vector<std::string> out;
  out.push_back(row("server", server + " (session " + session.at("session_dir").get<std::string>() +
                                  ", started " + session.at("started").get<std::string>() + ")"));
  const auto bridges = session.at("bridges").get<std::int64_t>();
  out.push_back(
      row("connection",
          bridges == 0 ? "no robot bridge connected: scans and moves cannot be sent"
                       : plural(bridges, "robot bridge", "robot bridges") + " connected over DDS"));
  std::string scan_line = plural(session.at("scans").get<std::int64_t>(), "scan", "scans") + ", " +
                          std::to_string(session.at("points").get<std::int64_t>()) +
                          " points in the map";
  if (const auto pending = scans.value("pending", 0); pending > 0) {
    scan_line += " (" + std::to_string(pending) + " more being processed)";
  }
  out.push_back(row("scans", scan_line));
  const json& a = session.at("areas");
  out.push_back(
      row("areas", "completed " + fixed(a.at("completed_m2").get<double>(), 0) + " m2, low-res " +
                       fixed(a.at("low_resolution_m2").get<double>(), 0) + " m2, unscanned " +
                       fixed(a.at("unscanned_m2").get<double>(), 0) + " m2, movable " +
                       fixed(a.at("movable_m2").get<double>(), 0) + " m2"));
  if (const auto m = session.find("mission"); m != session.end() && m->is_object()) {
    const std::string state = m->value("state", "");
    std::string text = fixed(m->value("coverage_pct", 0.0), 0) + " % of the area scanned";
    if (state == "finished") {
      text = "finished by " + m->value("finished_by", std::string("?")) + " at " +
             m->value("finished_at", std::string("?")) + "; " + text;
    } else if (state == "complete") {
      text = "complete: no suggested point adds more than " +
             fixed(m->value("threshold_m2", 0.0), 0) + " m2; " + text;
    } else {
      text += ", the next scan adds about " + fixed(m->value("best_gain_m2", 0.0), 0) + " m2";
      if (const auto left = m->find("scans_left"); left != m->end() && left->is_number()) {
        text += ", about " + std::to_string(left->get<int>()) + " more scans";
      }
    }
    out.push_back(row("mission", text));
  }

  const json& robots = session.at("robots");
  if (robots.empty()) out.push_back(row("robots", "none has reported yet"));
  std::vector<std::string> scanning;
  bool first = true;
  for (const auto& [id, r] : robots.items()) {
    std::string line = id + " " + r.at("state").get<std::string>();
    if (r.at("command_id").get<std::int64_t>() != 0) {
      line += " (command " + r.at("command_id").dump() + ")";
    }
    line += ", " + pose_text(r.at("pose"));
    if (const std::string m = r.value("message", ""); !m.empty()) line += ": " + m;
    out.push_back(row(first ? "robots" : "", line));
    first = false;
    const json& s = r.at("scan");
    const std::string state = s.at("state").get<std::string>();
    // A robot that was never asked to scan reports "idle" with command 0: nothing to show.
    if (state.empty() || s.at("command_id").get<std::int64_t>() == 0) continue;
    std::string scan = id + " scan command " + s.at("command_id").dump() + " " + state;
    if (state == "scanning") {
      scan += " " + progress_bar(s.at("fraction").get<double>());
    }
    if (const std::string m = s.value("message", ""); !m.empty()) scan += ": " + m;
    scanning.push_back(scan);
  }
  if (scanning.empty()) out.push_back(row("scanning", "no scan command so far"));
  for (std::size_t k = 0; k < scanning.size(); ++k) {
    out.push_back(row(k == 0 ? "scanning" : "", scanning[k]));
  }

  if (!session.contains("last_scan")) {
    out.push_back(row("last scan", "none yet: request one with POST /api/v1/scan"));
    return out;
  }
  const json& last = session.at("last_scan");
  out.push_back(row("last scan", "#" + last.at("id").dump() + " from " +
                                     last.at("robot").get<std::string>() + ", " +
                                     std::to_string(last.at("points").get<std::int64_t>()) +
                                     " points, placed " + pose_text(last.at("pose"))));
  const json& list = scans.at("scans");
  if (list.empty()) return out;
  const json& s = list.back();
  const json& e = s.at("estimated");
  const json& p = s.at("placed");
  const double dx = p.at("x").get<double>() - e.at("x").get<double>();
  const double dy = p.at("y").get<double>() - e.at("y").get<double>();
  const double dz = p.at("z").get<double>() - e.at("z").get<double>();
  const double dyaw = wrap_deg(p.at("yaw_deg").get<double>() - e.at("yaw_deg").get<double>());
  const std::string id = s.at("id").dump();
  std::string match;
  if (dx == 0 && dy == 0 && dz == 0 && dyaw == 0) {
    match = list.size() == 1 ? "scan " + id + " is the first: it defines the map frame"
                             : "scan " + id + " kept the robot's estimated pose (no match applied)";
  } else {
    match = "scan " + id + " moved " + fixed(std::hypot(dx, dy), 2) + " m by matching: dx " +
            signed_fixed(dx, 2) + " dy " + signed_fixed(dy, 2) + " dz " + signed_fixed(dz, 2) +
            " m, dyaw " + signed_fixed(dyaw, 1) + " deg";
  }
  out.push_back(row("last match", match));
  return out;
}

}  // namespace scanplan::cli
