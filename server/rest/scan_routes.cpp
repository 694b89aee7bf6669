#include "rest/api.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "app/domain_json.hpp"
#include "app/scan_intake.hpp"
#include "common/text_fields.hpp"
#include "http/http_error.hpp"
#include "rest/request_parsing.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Request;
using http::Response;
using nlohmann::json;
using rest::query_number;
using rest::query_scan_id;

Response Api::map_drc(const Request& request) const {
  LiveMap::EncodedMap encoded;
  const bool has_since = request.query.count("since") > 0;
  const bool has_until = request.query.count("until") > 0;
  if (has_until) {
    const std::int64_t since = has_since ? query_scan_id(request, "since") : 0;
    const std::int64_t until = query_scan_id(request, "until");
    if (until < since) {
      throw HttpError(400, "bad_request", "'until' must not be less than 'since'");
    }
    encoded = app_.map.encoded_range(since, until);
  } else if (has_since) {
    encoded = app_.map.encoded_since(query_scan_id(request, "since"));
  } else {
    encoded = app_.map.encoded_map();
  }
  Response r;
  if (encoded.draco) {
    // Shared with the map, not copied: many clients fetching it cost one buffer.
    r = Response::shared(encoded.draco, "application/octet-stream");
  } else {
    r.status = 204;
  }
  r.set_header("Cache-Control", "no-store");
  // The newest scan included, for the next ?since=.
  r.set_header("X-Scanplan-Last-Scan", std::to_string(encoded.last_scan));
  return r;
}

Response Api::layer(const std::string& name) const {
  const auto& names = LiveMap::layer_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw HttpError(404, "unknown_layer",
                    "no layer '" + name + "'; the layers are regions, elevation and movable");
  }
  const LayerImage image = app_.map.layer(name);
  if (!image.png) {
    Response empty;
    empty.status = 204;
    return empty;
  }
  Response r = Response::shared(image.png, "image/png");
  r.set_header("Cache-Control", "no-store");
  // Where the image lies in the map: its left, bottom, right and top edges in metres.
  const LayerGeometry& g = image.geometry;
  r.set_header("X-Scanplan-Layer-Bounds", std::to_string(g.min_x) + "," + std::to_string(g.min_y) +
                                              "," + std::to_string(g.max_x) + "," +
                                              std::to_string(g.max_y));
  // What the elevation layer's colours mean: the heights (m) of the first and last colour.
  if (image.height_range) {
    r.set_header("X-Scanplan-Layer-Range", std::to_string(image.height_range->lo) + "," +
                                               std::to_string(image.height_range->hi));
  }
  return r;
}

Response Api::post_scan(const Request& request) {
  Pose estimated;
  estimated.x = query_number(request, "x");
  estimated.y = query_number(request, "y");
  estimated.z = query_number(request, "z");
  estimated.yaw = deg2rad(query_number(request, "yaw_deg"));
  std::string robot = "robot1";
  if (const auto it = request.query.find("robot"); it != request.query.end()) robot = it->second;
  if (const auto why = robot_id_problem(robot)) throw HttpError(400, "bad_request", *why);
  if (request.body.empty()) {
    throw HttpError(400, "bad_request", "the body must be the scan as a PLY or PCD file");
  }
  PointCloud cloud;
  try {
    cloud = read_point_cloud_bytes(request.body, "the uploaded scan");
  } catch (const ScanFileError& e) {
    throw HttpError(400, "bad_scan", e.what());
  }
  const auto stamp = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
  try {
    const SubmittedScan s = app_.intake.submit(robot, estimated, stamp, std::move(cloud));
    json answer = scan_json(s.scan, std::nullopt, /*in_map=*/false);  // not processed yet
    answer["dropped"] = dropped_json(s.dropped);
    return Response::json(201, answer);
  } catch (const InvalidScanError& e) {
    throw HttpError(400, "bad_request", e.what());
  } catch (const UnusableScanError& e) {
    throw HttpError(422, "too_few_points", e.what());
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the scan could not be stored: ") + e.what());
  }
}

// A scan of the live map, with why it waits outside the map when it does.
json Api::live_scan_json(const StoredScan& s,
                         const std::map<std::int64_t, std::string>& waiting) const {
  const auto it = waiting.find(s.id);
  if (it == waiting.end()) return scan_json(s, app_.map.areas_after(s.id), /*in_map=*/true);
  return scan_json(s, app_.map.areas_after(s.id), /*in_map=*/false, it->second);
}

Response Api::list_scans() const {
  json list = json::array();
  const std::map<std::int64_t, std::string> waiting = app_.map.waiting_reasons();
  for (const StoredScan& s : app_.map.scans()) list.push_back(live_scan_json(s, waiting));
  json excluded = json::array();
  for (const StoredScan& s : app_.intake.excluded_scans()) {
    excluded.push_back(scan_json(s, app_.map.areas_after(s.id), false));
  }
  return Response::json(200, {{"scans", list},
                              {"pending", app_.intake.pending()},
                              {"excluded", excluded},
                              {"not_in_map", not_in_map_json(app_.intake.not_in_map())}});
}

Response Api::set_scan_excluded(const Request& request, const std::string& id, bool excluded) {
  const auto n = static_cast<std::int64_t>(rest::path_id(id, "a scan id"));
  const json body = rest::by_and_reason(request);
  const std::string by = rest::decided_by(body);
  const std::string reason = rest::text_in(body, "reason", rest::kMaxReasonBytes, TextKind::kProse);
  try {
    const StoredScan s = app_.intake.set_excluded(n, excluded, by, reason);
    return Response::json(200, scan_json(s, app_.map.areas_after(s.id), !excluded));
  } catch (const ExclusionError& e) {
    throw HttpError(e.code == "not_found" ? 404 : 409, e.code, e.what());
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the session could not record it: ") + e.what());
  }
}

Response Api::get_scan(const std::string& id) const {
  const auto n = static_cast<std::int64_t>(rest::path_id(id, "a scan id"));
  const std::map<std::int64_t, std::string> waiting = app_.map.waiting_reasons();
  for (const StoredScan& s : app_.map.scans()) {
    if (s.id == n) return Response::json(200, live_scan_json(s, waiting));
  }
  for (const StoredScan& s : app_.intake.excluded_scans()) {
    if (s.id == n) return Response::json(200, scan_json(s, app_.map.areas_after(s.id), false));
  }
  throw HttpError(404, "not_found", "no scan " + id + " in this session");
}

Response Api::request_scan(const Request& request) {
  std::string robot;
  if (const auto it = request.query.find("robot"); it != request.query.end()) {
    robot = it->second;
    if (const auto why = robot_id_problem(robot)) throw HttpError(400, "bad_request", *why);
  }
  try {
    const std::uint32_t id = app_.dds.request_scan(robot);
    return Response::json(202, {{"command_id", id}, {"robot", robot.empty() ? "*" : robot}});
  } catch (const NoScannerError& e) {
    throw HttpError(503, "no_scanner", e.what());
  }
}

}  // namespace scanplan::server
