#include "app/events.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>

#include "common/iso_time.hpp"
#include "http/websocket_hub.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

void Events::publish(const std::string& type, nlohmann::json data) const {
  if (!hub_) return;
  data["type"] = type;
  // Milliseconds: events of one scan come within a second, and latencies are read from them.
  data["at"] = iso8601_utc_now(TimePrecision::kMilliseconds);
  try {
    hub_->broadcast_text(data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  } catch (const std::exception& e) {
    spdlog::warn("event '{}' not sent: {}", type, e.what());
  }
}

void publish_recorded(const Events& events, SessionStore& session, const std::string& type,
                      const nlohmann::json& details) {
  events.publish(type, details);
  try {
    session.append_event(type, details.dump());
  } catch (const std::exception& e) {
    spdlog::error("could not record '{}' in the session: {}", type, e.what());
  }
}

void Events::map_chunk(std::int64_t scan_id, const std::string& draco) const {
  if (!hub_) return;
  try {
    hub_->broadcast_binary(kMapChunkOp, static_cast<std::uint32_t>(scan_id), draco);
  } catch (const std::exception& e) {
    spdlog::warn("map chunk of scan {} not sent: {}", scan_id, e.what());
  }
}

}  // namespace scanplan::server
