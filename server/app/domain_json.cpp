#include "app/domain_json.hpp"

#include <cmath>

namespace scanplan::server {

using nlohmann::json;

json pose_json(const Pose& p) {
  return {{"x", p.x}, {"y", p.y}, {"z", p.z}, {"yaw_deg", rad2deg(p.yaw)}};
}

json areas_json(const MapAreas& a) {
  return {{"completed_m2", a.completed_m2},
          {"low_resolution_m2", a.low_resolution_m2},
          {"unscanned_m2", a.unscanned_m2},
          {"movable_m2", a.movable_m2}};
}

json progress_json(const MissionProgress& p) {
  json j = {{"state", p.state},
            {"coverage_pct", p.coverage_pct},
            {"best_gain_m2", p.best_gain_m2},
            {"best_left_m2", p.best_left_m2},
            {"threshold_m2", p.threshold_m2},
            {"scans_left", p.scans_left ? json(*p.scans_left) : json(nullptr)}};
  if (p.state == "finished") {
    j["finished_by"] = p.finished_by;
    j["finished_at"] = p.finished_at;
  }
  return j;
}

json layer_geometry_json(const LayerGeometry& g) {
  return {{"min", {g.min_x, g.min_y}},
          {"max", {g.max_x, g.max_y}},
          {"px_per_m", g.px_per_m},
          {"width", g.width},
          {"height", g.height}};
}

namespace {

json match_json(const std::optional<StoredMatch>& m) {
  if (!m) return nullptr;
  return {{"applied", m->applied},
          {"converged", m->converged},
          {"method", m->method},
          {"reason", m->reason},
          {"time_ms", m->time_ms},
          {"inlier_ratio", m->inlier_ratio},
          {"weakest_constraint", m->weakest_constraint}};
}

}  // namespace

json not_in_map_json(const std::vector<ScanIntake::NotInMap>& scans) {
  json out = json::array();
  for (const auto& s : scans)
    out.push_back({{"id", s.id}, {"robot", s.robot}, {"reason", s.reason}});
  return out;
}

json dropped_json(const DroppedReturns& d) {
  return {{"non_finite", d.non_finite},
          {"out_of_range", d.out_of_range},
          {"mount", d.mount},
          {"saturated", d.saturated}};
}

json scan_json(const StoredScan& s, const std::optional<MapAreas>& areas, bool in_map,
               const std::optional<std::string>& outside) {
  return {{"id", s.id},
          {"in_map", in_map},
          {"outside", outside ? json(*outside) : json(nullptr)},
          {"robot", s.robot},
          {"points", s.points},
          {"estimated", pose_json(s.estimated)},
          {"placed", pose_json(s.placed)},
          {"goal", s.goal ? json{{"x", s.goal->x()},
                                 {"y", s.goal->y()},
                                 {"z", s.goal->z()},
                                 {"drive_m", s.goal_drive_m}}
                          : json(nullptr)},
          {"received_at", s.received_at},
          {"match", match_json(s.match)},
          {"areas", areas ? areas_json(*areas) : json(nullptr)},
          {"excluded", s.excluded ? json{{"by", s.excluded->by},
                                         {"reason", s.excluded->reason},
                                         {"at", s.excluded->at}}
                                  : json(nullptr)}};
}

json candidate_json(const CandidateRecord& r, const std::string& robot, std::uint64_t plan) {
  const Candidate& c = r.candidate;
  json path = json::array();
  for (const auto& p : c.path) path.push_back({p.x(), p.y()});
  json registrability = nullptr;
  if (c.registrability) {
    registrability = {{"overlap_share", c.registrability->overlap_share},
                      {"pose_fixing", c.registrability->pose_fixing},
                      {"reach", c.registrability->reach},
                      {"factor", c.registrability->factor}};
    if (const auto& v = c.registrability->predicted_constraint) {
      registrability["predicted_constraint"] = *v;
    }
  }
  return {{"id", r.id},
          {"robot", robot},
          {"plan", plan},
          {"rank", r.rank},
          {"state", to_string(r.state)},
          {"note", r.note},
          {"custom", r.custom},
          {"x", c.position.x()},
          {"y", c.position.y()},
          {"z", c.position.z()},
          {"f", c.f},
          {"gain_unscanned_m2", c.gain_unscanned_m2},
          {"gain_low_res_m2", c.gain_low_res_m2},
          {"overlap_m2", c.overlap_m2},
          {"registrability", registrability},
          {"travel_m", c.travel_m},
          {"score", c.score},
          {"path", path}};
}

json plan_header_json(const PlanRecord& p) {
  return {{"id", p.id},
          {"based_on_scan", p.based_on_scan},
          {"robot", p.robot},
          {"policy", p.policy},
          {"alpha", p.alpha},
          {"plan_ms", p.plan_ms},
          {"best_gain_m2", p.best_gain_m2},
          {"candidates", p.candidates.size()}};
}

json robot_json(const RobotState& r) {
  const bool connected = r.connection.connected;
  return {{"connected", connected},
          {"lost_at", connected ? json(nullptr) : json(r.connection.lost_at)},
          {"lost_reason", connected ? json(nullptr) : json(r.connection.reason)},
          {"state", to_string(r.status.state)},
          {"command_id", r.status.command_id},
          {"message", r.status.message},
          {"pose", pose_json(r.status.reported)},
          {"scan",
           {{"command_id", r.scan.command_id},
            {"state", to_string(r.scan.state)},
            {"fraction", r.scan.fraction},
            {"message", r.scan.message}}}};
}

json annotation_json(const Annotation& a) {
  return {{"id", a.id}, {"kind", a.kind}, {"x", a.x},           {"y", a.y},
          {"z", a.z},   {"text", a.text}, {"author", a.author}, {"created_at", a.created_at}};
}

namespace {

json corners_json(const TargetRegion& region) {
  json corners = json::array();
  for (const auto& c : region.corners()) corners.push_back({c.x(), c.y()});
  return corners;
}

}  // namespace

json params_json(const MissionParams& p) {
  json target = nullptr;
  if (p.target) target = corners_json(*p.target);
  json no_go = json::array();
  for (const TargetRegion& zone : p.planner.no_go) no_go.push_back(corners_json(zone));
  return {{"alpha", p.planner.alpha},
          {"policy", std::string(policy_name(p.planner.policy))},
          {"max_candidates", p.planner.max_candidates},
          {"travel_cost_per_m", p.planner.travel_cost_per_m},
          {"travel_free_m", p.planner.travel_free_m},
          {"completed_radius_m", p.planner.regions.completed_radius_m},
          {"max_step_m", p.planner.movable.max_step_m},
          {"target", target},
          {"no_go", no_go}};
}

json approval_json(const Approval& a) {
  return {{"candidate", a.candidate},
          {"robot", a.robot},
          {"command_id", a.command_id},
          {"x", a.x},
          {"y", a.y},
          {"yaw_deg", a.yaw_deg},
          {"by", a.by}};
}

json rejection_json(const Rejection& r) {
  return {{"candidate", r.candidate}, {"by", r.by}, {"reason", r.reason}};
}

json cancellation_json(const Cancellation& c) {
  return {{"candidate", c.candidate}, {"robot", c.robot}, {"by", c.by}};
}

json proposal_json(const Proposal& p, const std::string& by) {
  const Candidate& c = p.candidate.candidate;
  return {{"candidate", p.candidate.id},
          {"robot", p.robot},
          {"x", c.position.x()},
          {"y", c.position.y()},
          {"f", c.f},
          {"travel_m", c.travel_m},
          {"by", by}};
}

json decision_json(const SessionEvent& e) {
  json entry = json::parse(e.json, nullptr, false);
  if (!entry.is_object()) entry = json::object();
  entry["id"] = e.id;
  entry["at"] = e.at;
  entry["kind"] = e.kind;
  return entry;
}

json match_done_json(std::int64_t scan, const Pose& e, const MapMatch& m) {
  const Pose& p = m.placed;
  return {{"scan", scan},
          {"method", m.result.method},
          {"converged", m.result.converged},
          {"applied", m.applied},
          {"score", m.result.score},
          {"rmse", m.result.rmse},
          {"time_ms", m.result.time_ms},
          {"message", m.result.message},
          {"correction",
           {{"x", p.x - e.x},
            {"y", p.y - e.y},
            {"z", p.z - e.z},
            {"yaw_deg", rad2deg(std::remainder(p.yaw - e.yaw, 2 * M_PI))}}}};
}

json map_updated_json(const StoredScan& scan, const MapAreas& a, bool in_map,
                      const std::string& outside, json stages_ms) {
  return {{"scan", scan.id},
          {"points", scan.points},
          {"in_map", in_map},
          {"outside", in_map ? json(nullptr) : json(outside)},
          {"completed_m2", a.completed_m2},
          {"low_resolution_m2", a.low_resolution_m2},
          {"unscanned_m2", a.unscanned_m2},
          {"movable_m2", a.movable_m2},
          {"stages_ms", std::move(stages_ms)}};
}

json map_corrected_json(const MapCorrected& c, std::int64_t revision) {
  return {{"scans", c.moved},
          {"joined", c.joined},
          {"left", c.left},
          {"max_moved_m", c.max_moved_m},
          {"max_turned_deg", c.max_turned_deg},
          {"revision", revision}};
}

json plan_done_json(const PlanRecord& plan) {
  return {{"plan", plan.id},
          {"robot", plan.robot},
          {"based_on_scan", plan.based_on_scan},
          {"candidates", plan.candidates.size()},
          {"plan_ms", plan.plan_ms}};
}

json scan_progress_json(const std::string& robot, const RobotScanState& s) {
  return {{"robot", robot},
          {"command_id", s.command_id},
          {"state", to_string(s.state)},
          {"fraction", s.fraction},
          {"message", s.message}};
}

json robot_status_json(const std::string& robot, const RobotStatus& s) {
  return {{"robot", robot},
          {"command_id", s.command_id},
          {"state", to_string(s.state)},
          {"message", s.message},
          {"pose", pose_json(s.reported)}};
}

}  // namespace scanplan::server
