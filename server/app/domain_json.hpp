#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "app/live_map.hpp"
#include "app/mission.hpp"
#include "app/mission_progress.hpp"
#include "app/plan_book.hpp"
#include "app/robot_board.hpp"
#include "app/scan_intake.hpp"
#include "scanplan/geometry/scan_returns.hpp"
#include "scanplan/registration/map_matcher.hpp"
#include "storage/session_store.hpp"

// The JSON of the session's domain types, in one place: what the REST API answers, what the
// WebSocket events carry and what the session's event log records are the same encodings
// (docs/api.md).
namespace scanplan::server {

nlohmann::json pose_json(const Pose& p);  // {x, y, z, yaw_deg}
nlohmann::json areas_json(const MapAreas& a);
nlohmann::json progress_json(const MissionProgress& p);
nlohmann::json layer_geometry_json(const LayerGeometry& g);
// Scans the session holds that are not in the map, and why: [{id, robot, reason}].
nlohmann::json not_in_map_json(const std::vector<ScanIntake::NotInMap>& scans);
// What drop_bad_returns left out of a scan, by kind.
nlohmann::json dropped_json(const DroppedReturns& d);
// `in_map`: false for a scan waiting outside the map for a match that ties it in (and for
// one the operator took out); `outside`: why such a scan waits (LiveMap::waiting_reasons), null
// when not given.
nlohmann::json scan_json(const StoredScan& s, const std::optional<MapAreas>& areas, bool in_map,
                         const std::optional<std::string>& outside = std::nullopt);
nlohmann::json candidate_json(const CandidateRecord& r, const std::string& robot,
                              std::uint64_t plan);
// A plan without its candidates: {id, based_on_scan, robot, policy, alpha, plan_ms, candidates}.
nlohmann::json plan_header_json(const PlanRecord& p);
nlohmann::json robot_json(const RobotState& r);
nlohmann::json annotation_json(const Annotation& a);
nlohmann::json params_json(const MissionParams& p);

nlohmann::json approval_json(const Approval& a);
nlohmann::json rejection_json(const Rejection& r);
nlohmann::json cancellation_json(const Cancellation& c);
// The "goal" record of the operator's own point.
nlohmann::json proposal_json(const Proposal& p, const std::string& by);
// One entry of the decision log: the recorded details with {id, at, kind}.
nlohmann::json decision_json(const SessionEvent& e);

// Event payloads (docs/api.md "Events").
nlohmann::json match_done_json(std::int64_t scan, const Pose& estimated, const MapMatch& m);
// `stages_ms`: where the scan's way into the map went (ScanIntake::process); `outside`: why it
// waits outside the map when it does (LiveMap::Added).
nlohmann::json map_updated_json(const StoredScan& scan, const MapAreas& a, bool in_map,
                                const std::string& outside, nlohmann::json stages_ms);
// The pose graph moved scans, or tied them into the map or set them outside it (revision: the
// session's pose revision that records it; 0 when it could not be recorded).
nlohmann::json map_corrected_json(const MapCorrected& c, std::int64_t revision);
nlohmann::json plan_done_json(const PlanRecord& plan);
nlohmann::json scan_progress_json(const std::string& robot, const RobotScanState& s);
nlohmann::json robot_status_json(const std::string& robot, const RobotStatus& s);

}  // namespace scanplan::server
