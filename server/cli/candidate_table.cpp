#include "candidate_table.hpp"

#include <cstdio>

#include "text_format.hpp"

namespace scanplan::cli {
namespace {

// The matcher's forecast at a candidate: the share of the scan predicted on the trusted map,
// marked "?" where the planner expects the match to fail; "-" without a forecast (matching
// off, the operator's own points, a plan from before a restart).
std::string match_forecast(const nlohmann::json& c) {
  const auto it = c.find("registrability");
  if (it == c.end() || !it->is_object()) return "- ";
  const double share = it->at("overlap_share").get<double>();
  const bool doubtful = it->at("factor").get<double>() < 1;
  // The percent signs stay in one column; a trailing space is trimmed off the row.
  return fixed(100 * share, 0) + "%" + (doubtful ? "?" : " ");
}

}  // namespace

std::vector<std::string> render_candidate_table(const nlohmann::json& answer) {
  std::vector<std::string> out;
  const nlohmann::json& plan = answer.at("plan");
  if (plan.is_null()) {
    out.emplace_back("no plan yet: the planner proposes scan points after the first scan");
    return out;
  }
  // Several robots: one plan each (the newest first), and a robot column in the table.
  const nlohmann::json plans =
      answer.contains("plans") ? answer.at("plans") : nlohmann::json::array({plan});
  const bool several = plans.size() > 1;
  for (const nlohmann::json& p : plans) {
    out.push_back("plan " + p.at("id").dump() + " after scan " + p.at("based_on_scan").dump() +
                  " (robot " + p.at("robot").get<std::string>() + ", policy " +
                  p.at("policy").get<std::string>() + ", alpha " +
                  fixed(p.at("alpha").get<double>(), 2) + ", planned in " +
                  fixed(p.at("plan_ms").get<double>(), 0) + " ms)");
  }
  const nlohmann::json& list = answer.at("candidates");
  if (list.empty()) {
    out.emplace_back("no candidates: the planner found no reachable point that sees anything new");
    return out;
  }
  char line[256];
  const auto robot_column = [&](const std::string& robot) {
    if (!several) return std::string();
    char cell[32];
    std::snprintf(cell, sizeof cell, "%-10.10s ", robot.c_str());
    return std::string(cell);
  };
  std::snprintf(line, sizeof line, "%4s %6s  %-10s %8s %8s %9s %10s %10s %9s %6s", "rank", "id",
                "state", "x m", "y m", "F", "gain U m2", "gain M m2", "travel m", "match");
  out.push_back(robot_column("robot") + line);
  for (const nlohmann::json& c : list) {
    std::snprintf(
        line, sizeof line, "%4d %6s  %-10s %8s %8s %9s %10s %10s %9s %7s", c.at("rank").get<int>(),
        c.at("id").dump().c_str(), c.at("state").get<std::string>().c_str(),
        fixed(c.at("x").get<double>(), 1).c_str(), fixed(c.at("y").get<double>(), 1).c_str(),
        fixed(c.at("f").get<double>(), 1).c_str(),
        fixed(c.at("gain_unscanned_m2").get<double>(), 1).c_str(),
        fixed(c.at("gain_low_res_m2").get<double>(), 1).c_str(),
        fixed(c.at("travel_m").get<double>(), 1).c_str(), match_forecast(c).c_str());
    std::string row = robot_column(c.value("robot", "")) + line;
    const std::string note = c.value("note", "");
    if (!note.empty()) {
      row += " (" + note + ")";
    } else {
      row.erase(row.find_last_not_of(' ') + 1);
    }
    out.push_back(row);
  }
  return out;
}

std::string describe_candidate(const nlohmann::json& c) {
  return std::to_string(c.at("rank").get<int>()) + ". candidate " + c.at("id").dump() + " at " +
         position(c.at("x").get<double>(), c.at("y").get<double>()) + ": F " +
         fixed(c.at("f").get<double>(), 1) + ", gains U " +
         fixed(c.at("gain_unscanned_m2").get<double>(), 1) + " + M " +
         fixed(c.at("gain_low_res_m2").get<double>(), 1) + " m2, travel " +
         fixed(c.at("travel_m").get<double>(), 1) + " m, " + c.at("state").get<std::string>();
}

}  // namespace scanplan::cli
