// Exports for other teams (DESIGN.md "REST", issue 18): the registered map as PLY and LAS, the
// scans' poses as CSV, the annotations as GeoJSON, all in the map frame.
#include <ctime>
#include <memory>

#include "app/exports.hpp"
#include "app/mission_report.hpp"
#include "common/iso_time.hpp"
#include "http/http_error.hpp"
#include "rest/api.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Response;

Response Api::export_file(const std::string& name) const {
  std::string body;
  std::string type;
  if (name == "map.ply" || name == "map.las") {
    const LiveMap::Held held = app_.map.held();
    if (held.parts.empty()) {
      throw HttpError(409, "no_map", "there is no map to export yet: take a first scan");
    }
    if (name == "map.ply") {
      body = map_ply_bytes(held.parts, {"scanplan registered map, map frame (metres)",
                                        "scan_id: the scan each point came from"});
      type = "application/octet-stream";
    } else {
      try {
        body = map_las_bytes(held.parts, std::time(nullptr));
      } catch (const std::invalid_argument& e) {
        throw HttpError(409, "not_exportable", e.what());
      }
      type = "application/vnd.las";
    }
  } else if (name == "poses.csv") {
    body = poses_csv(app_.map.held().scans);
    type = "text/csv; charset=utf-8";
  } else if (name == "annotations.geojson") {
    body = annotations_geojson(app_.annotations.list());
    type = "application/geo+json";
  } else {
    throw HttpError(
        404, "unknown_export",
        "no export '" + name + "'; there are map.ply, map.las, poses.csv and annotations.geojson");
  }
  // Shared, not copied: a whole map is hundreds of megabytes.
  Response r = Response::shared(std::make_shared<const std::string>(std::move(body)), type);
  r.set_header("Content-Disposition", "attachment; filename=\"scanplan-" + name + "\"");
  r.set_header("Cache-Control", "no-store");
  return r;
}

Response Api::report() const {
  ReportInput in;
  in.session_dir = session_dir_;
  in.generated_at = iso8601_utc_now();
  in.scans = app_.map.scans();
  in.waiting = app_.map.waiting_reasons();
  in.areas = app_.map.areas();
  for (const StoredScan& s : in.scans) {
    if (const auto a = app_.map.areas_after(s.id)) in.areas_after[s.id] = *a;
  }
  in.params = app_.map.params();
  in.regions = app_.map.layer("regions");
  in.annotations = app_.annotations.list();
  try {
    in.decisions = app_.mission.log(100000);
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed", std::string("the session cannot be read: ") + e.what());
  }
  Response r = Response::bytes(mission_report_html(in), "text/html; charset=utf-8");
  r.set_header("Cache-Control", "no-store");
  return r;
}

}  // namespace scanplan::server
