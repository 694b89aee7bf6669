#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/live_map.hpp"
#include "storage/session_store.hpp"

// The mission report for other teams and the record (issue 18): one self-contained, printable
// HTML page — the top view with the marks on it, the marks with coordinates and who made them
// when, the scans with their match results, the decisions and the coverage after each scan.
namespace scanplan::server {

struct ReportInput {
  std::string session_dir;
  std::string generated_at;  // UTC, ISO 8601
  std::vector<StoredScan> scans;
  // Scans outside the map, waiting for a match, and why (LiveMap::waiting_reasons).
  std::map<std::int64_t, std::string> waiting;
  MapAreas areas;
  std::map<std::int64_t, MapAreas> areas_after;  // by scan id
  MissionParams params;
  LayerImage regions;  // the regions layer; no image before the first scan
  std::vector<Annotation> annotations;
  std::vector<SessionEvent> decisions;  // oldest first
};

std::string mission_report_html(const ReportInput& in);

}  // namespace scanplan::server
