#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace scanplan {
class SessionStore;
}

namespace scanplan::http {
class WebSocketHub;
}

namespace scanplan::server {

// What happens in the session, pushed to every browser on GET /api/v1/events: JSON text frames
// {"type", "at", ...} and binary map chunks (one Draco point cloud per scan). Without a hub
// (offline tools, tests) events go nowhere.
class Events {
 public:
  explicit Events(http::WebSocketHub* hub = nullptr) : hub_(hub) {}

  // Event types (docs/api.md): scan_progress, robot_status, scan_received, map_updated,
  // match_done, plan_done, mission, annotation, annotation_deleted, robot_lost, robot_back,
  // scan_failed, map_corrected; the hub adds binary_dropped.
  void publish(const std::string& type, nlohmann::json data) const;
  // The new points of scan `scan_id` in the map frame, Draco-encoded: binary frame op 1.
  void map_chunk(std::int64_t scan_id, const std::string& draco) const;

  static constexpr std::uint8_t kMapChunkOp = 1;

 private:
  http::WebSocketHub* hub_;
};

// Published, and kept in the session's record of what happened (GET /api/v1/decisions), so a
// page that reloads reads it back. A record the disk refuses is logged; the event goes out.
void publish_recorded(const Events& events, SessionStore& session, const std::string& type,
                      const nlohmann::json& details);

}  // namespace scanplan::server
