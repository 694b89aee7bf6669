#include "event_text.hpp"

#include <string>
#include <vector>

#include "text_format.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

std::string str(const json& e, const char* key) {
  const auto it = e.find(key);
  if (it == e.end() || it->is_null()) return "";
  return it->is_string() ? it->get<std::string>() : it->dump();
}

double num(const json& e, const char* key) {
  const auto it = e.find(key);
  return it != e.end() && it->is_number() ? it->get<double>() : 0.0;
}

std::string with_message(std::string text, const json& e) {
  if (const std::string m = str(e, "message"); !m.empty()) text += ": " + m;
  return text;
}

std::string by(const json& e) {
  const std::string who = str(e, "by");
  return who.empty() ? "" : " by " + who;
}

std::string scan_progress(const json& e) {
  const std::string state = str(e, "state");
  std::string text = str(e, "robot") + " scan command " + str(e, "command_id") + " ";
  if (state == "failed") {
    return with_message(text + "FAILED at " + fixed(100 * num(e, "fraction"), 0) + "%", e);
  }
  return with_message(text + progress_bar(num(e, "fraction")) + " " + state, e);
}

std::string scan_received(const json& e) {
  std::string text = "scan " + str(e, "scan") + " from " + str(e, "robot") +
                     " stored: " + str(e, "points") + " points";
  const auto d = e.find("dropped");
  if (d == e.end() || !d->is_object()) return text;
  const double non_finite = num(*d, "non_finite"), out_of_range = num(*d, "out_of_range"),
               mount = num(*d, "mount"), saturated = num(*d, "saturated");
  if (non_finite + out_of_range + mount + saturated > 0) {
    text += " (dropped " + fixed(non_finite, 0) + " not finite, ";
    if (out_of_range > 0) text += fixed(out_of_range, 0) + " out of range, ";
    text += fixed(mount, 0) + " on the mount, " + fixed(saturated, 0) + " saturated)";
  }
  return text;
}

std::string scan_rejected(const json& e) {
  return "scan from " + str(e, "robot") + " REFUSED: " + str(e, "reason");
}

std::string match_done(const json& e) {
  std::string text = "scan " + str(e, "scan") + ": " + str(e, "method") + " " +
                     (e.value("converged", false) ? "converged" : "did not converge") + ", score " +
                     fixed(num(e, "score"), 1) + ", rmse " + fixed(num(e, "rmse"), 3) + " m";
  const bool applied = e.value("applied", false);
  // A match that was not applied leaves the estimate as it was; its correction says nothing.
  if (const auto c = e.find("correction"); applied && c != e.end() && c->is_object()) {
    text += ", correction dx " + signed_fixed(num(*c, "x"), 2) + " dy " +
            signed_fixed(num(*c, "y"), 2) + " dz " + signed_fixed(num(*c, "z"), 2) + " m dyaw " +
            signed_fixed(num(*c, "yaw_deg"), 1) + " deg";
  }
  text += applied ? " (applied)" : " (NOT applied: the robot's estimate is kept)";
  text += ", " + fixed(num(e, "time_ms"), 0) + " ms";
  return with_message(text, e);
}

// Scan ids as runs: [3, 4, 5, 6, 9] -> "3–6, 9".
std::string id_runs(const json& ids) {
  std::vector<long long> v;
  if (ids.is_array()) {
    for (const json& id : ids) {
      if (id.is_number_integer()) v.push_back(id.get<long long>());
    }
  }
  std::string out;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j + 1 < v.size() && v[j + 1] == v[j] + 1) ++j;
    if (!out.empty()) out += ", ";
    out += std::to_string(v[i]);
    if (j > i) out += "\u2013" + std::to_string(v[j]);
    i = j + 1;
  }
  return out;
}

std::size_t count_of(const json& e, const char* key) {
  const auto it = e.find(key);
  return it != e.end() && it->is_array() ? it->size() : 0;
}

// "map corrected: scans 3–9 moved up to 12 cm / 0.1°; scan 14 tied into the map".
std::string map_corrected(const json& e) {
  std::vector<std::string> parts;
  const auto scans = [&](const char* key) {
    return (count_of(e, key) == 1 ? "scan " : "scans ") + id_runs(e.at(key));
  };
  if (count_of(e, "scans") > 0) {
    parts.push_back(scans("scans") + " moved up to " + fixed(100 * num(e, "max_moved_m"), 0) +
                    " cm / " + fixed(num(e, "max_turned_deg"), 1) + " deg");
  }
  if (count_of(e, "joined") > 0) parts.push_back(scans("joined") + " tied into the map");
  if (count_of(e, "left") > 0) {
    parts.push_back(scans("left") + " set outside the map until a match agrees again");
  }
  std::string text = "map corrected:";
  for (std::size_t i = 0; i < parts.size(); ++i) text += (i ? "; " : " ") + parts[i];
  if (num(e, "revision") > 0) text += " (pose revision " + str(e, "revision") + ")";
  return text;
}

std::string mission(const json& e) {
  const std::string kind = str(e, "kind");
  const std::string candidate = "candidate " + str(e, "candidate");
  if (kind == "approve") {
    return "approved " + candidate + by(e) + ": " + str(e, "robot") + " drives to " +
           position(num(e, "x"), num(e, "y")) + " heading " + fixed(num(e, "yaw_deg"), 0) +
           " deg (command " + str(e, "command_id") + ")";
  }
  if (kind == "reject") {
    const std::string reason = str(e, "reason");
    return "rejected " + candidate + by(e) + (reason.empty() ? "" : " (" + reason + ")");
  }
  if (kind == "cancel") return "cancelled " + candidate + by(e) + ": " + str(e, "robot") + " stops";
  if (kind == "arrived") {
    return with_message(str(e, "robot") + " arrived at " + candidate + "; a scan follows", e);
  }
  if (kind == "refused") {
    return with_message(str(e, "robot") + " refused to drive to " + candidate, e);
  }
  if (kind == "scan_requested") {
    const std::string after = str(e, "after");
    return "scan requested from " + str(e, "robot") + " (command " + str(e, "command_id") + ")" +
           (after.empty() ? "" : " after " + after);
  }
  if (kind == "params") {
    const auto p = e.find("params");
    const auto field = [&](const char* key) {
      return p != e.end() && p->is_object() && p->contains(key) && (*p)[key].is_array()
                 ? (*p)[key].size()
                 : std::size_t{0};
    };
    const std::size_t corners = field("target"), zones = field("no_go");
    return "parameters set" + by(e) + ": " +
           (corners ? "a target area of " + std::to_string(corners) + " corners"
                    : std::string("the default target area")) +
           ", " + std::to_string(zones) + (zones == 1 ? " no-go zone" : " no-go zones");
  }
  json rest = e;
  rest.erase("type");
  rest.erase("at");
  return rest.dump();
}

}  // namespace

std::optional<MapChunk> parse_map_chunk(std::string_view frame) {
  if (frame.size() < 13) return std::nullopt;
  const auto byte = [&](std::size_t i) {
    return static_cast<std::uint64_t>(static_cast<unsigned char>(frame[i]));
  };
  MapChunk c;
  c.op = static_cast<std::uint8_t>(byte(0));
  for (int k = 0; k < 4; ++k) c.id |= static_cast<std::uint32_t>(byte(1 + k) << (8 * k));
  for (int k = 0; k < 8; ++k) c.sent_ns |= byte(5 + k) << (8 * k);
  c.payload_bytes = frame.size() - 13;
  return c;
}

std::string describe_event(const json& e) {
  const std::string type = str(e, "type");
  if (type == "scan_progress") return scan_progress(e);
  if (type == "robot_status") {
    std::string text = str(e, "robot") + " " + str(e, "state");
    if (str(e, "command_id") != "0") text += " (command " + str(e, "command_id") + ")";
    if (const auto p = e.find("pose"); p != e.end() && p->is_object()) {
      text += " at " + position(num(*p, "x"), num(*p, "y")) + " heading " +
              fixed(num(*p, "yaw_deg"), 0) + " deg";
    }
    return with_message(text, e);
  }
  if (type == "scan_received") return scan_received(e);
  if (type == "scan_rejected") return scan_rejected(e);
  if (type == "match_done") return match_done(e);
  if (type == "map_corrected") return map_corrected(e);
  if (type == "map_updated") {
    const bool waiting = !e.value("in_map", true);
    // Why it waits, when the server says (older servers do not).
    const std::string why = e.contains("outside") && e.at("outside").is_string()
                                ? e.at("outside").get<std::string>()
                                : "";
    return "scan " + str(e, "scan") +
           (!waiting      ? " is in the map: completed "
            : why.empty() ? " waits outside the map until a match ties it in: completed "
                          : " waits outside the map (" + why + "): completed ") +
           fixed(num(e, "completed_m2"), 0) + " m2, low-res " +
           fixed(num(e, "low_resolution_m2"), 0) + " m2, unscanned " +
           fixed(num(e, "unscanned_m2"), 0) + " m2, movable " + fixed(num(e, "movable_m2"), 0) +
           " m2";
  }
  if (type == "scan_excluded" || type == "scan_restored") {
    const std::string reason = str(e, "reason");
    return "scan " + str(e, "scan") +
           (type == "scan_excluded" ? " taken out of the map by " : " put back into the map by ") +
           str(e, "by") + (reason.empty() ? "" : ": " + reason);
  }
  if (type == "map_rebuilt") {
    return "map rebuilt from " + str(e, "scans") + " scans: completed " +
           fixed(num(e, "completed_m2"), 0) + " m2, movable " + fixed(num(e, "movable_m2"), 0) +
           " m2";
  }
  if (type == "storage_failed") return "STORAGE FAILED: " + str(e, "message");
  if (type == "plan_done") {
    return "plan " + str(e, "plan") + " after scan " + str(e, "based_on_scan") + ": " +
           str(e, "candidates") + " candidates in " + fixed(num(e, "plan_ms"), 0) + " ms";
  }
  if (type == "mission") return mission(e);
  if (type == "annotation") {
    std::string text = str(e, "kind") + " #" + str(e, "id") + " at " +
                       position(num(e, "x"), num(e, "y")) + ", z " + fixed(num(e, "z"), 1) +
                       " by " + str(e, "author");
    if (const std::string t = str(e, "text"); !t.empty()) text += ": " + t;
    return text;
  }
  if (type == "annotation_deleted") return "#" + str(e, "id") + " deleted" + by(e);
  if (type == "binary_dropped") {
    return str(e, "count") + " map chunks (scans " + str(e, "first_id") + ".." + str(e, "last_id") +
           ") dropped: this link is too slow for them";
  }
  json rest = e;
  rest.erase("type");
  rest.erase("at");
  return rest.dump();
}

std::string describe_map_chunk(const MapChunk& c) {
  if (c.op != 1) {
    return "binary frame op " + std::to_string(c.op) + ", id " + std::to_string(c.id) + ": " +
           std::to_string(c.payload_bytes) + " bytes (not shown)";
  }
  return "scan " + std::to_string(c.id) + ": " + std::to_string(c.payload_bytes) +
         " bytes of Draco points (not shown)";
}

json map_chunk_json(const MapChunk& c) {
  return {{"type", "map_chunk"},
          {"op", c.op},
          {"scan", c.id},
          {"bytes", c.payload_bytes},
          {"sent_ns", c.sent_ns}};
}

}  // namespace scanplan::cli
