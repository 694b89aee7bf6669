#pragma once

#include <optional>
#include <string>
#include <vector>

#include "app/live_map.hpp"
#include "app/plan_book.hpp"

// How far the mission has come, for the operator (issue 18): the share of the target region
// scanned, what the next scan would still add, an estimate of the scans left, and whether the
// mission is complete (no suggested point adds enough) or the operator finished it.
namespace scanplan::server {

struct ProgressConfig {
  // Complete when no candidate of any robot, nor any place its plan looked at, would add more
  // than this share of the target region (unscanned or low-resolution ground it would
  // complete), and never less than
  // min_gain_m2: a scan for a few square metres is not worth a rescue robot's minute.
  double complete_share = 0.005;
  double min_gain_m2 = 50.0;
  // The estimate looks at this many of the latest scans' gains.
  int recent_scans = 5;
};

struct MissionProgress {
  std::string state;        // "running", "complete" or "finished"
  double coverage_pct = 0;  // scan-completed share of the target region
  double best_gain_m2 = 0;  // what the best suggested scan would add
  // What the best place any open plan looked at would add, suggested or not (Plan::best_gain_m2:
  // a place the matcher could not yet place a scan at is ranked behind, not done).
  double best_left_m2 = 0;
  double threshold_m2 = 0;               // below this a scan is not worth making
  std::optional<int> scans_left;         // while running, when the gains so far allow an estimate
  std::string finished_by, finished_at;  // "finished": who and when
};

// `after` is the areas after each scan in order (LiveMap::areas_after); `finished` the
// operator's finish (who, when), if it stands.
MissionProgress mission_progress(const MapAreas& now, const std::vector<MapAreas>& after,
                                 const std::vector<PlanRecord>& plans,
                                 const std::optional<std::pair<std::string, std::string>>& finished,
                                 const ProgressConfig& config = {});

}  // namespace scanplan::server
