#include "app/mission_progress.hpp"

#include <algorithm>
#include <cmath>

namespace scanplan::server {

MissionProgress mission_progress(const MapAreas& now, const std::vector<MapAreas>& after,
                                 const std::vector<PlanRecord>& plans,
                                 const std::optional<std::pair<std::string, std::string>>& finished,
                                 const ProgressConfig& config) {
  MissionProgress p;
  const double total = now.completed_m2 + now.low_resolution_m2 + now.unscanned_m2;
  p.coverage_pct = total > 0 ? 100 * now.completed_m2 / total : 0;
  p.threshold_m2 = std::max(config.min_gain_m2, config.complete_share * total);
  // A move under way counts as a suggestion still to be scanned.
  bool moving = false;
  for (const PlanRecord& plan : plans) {
    bool open = false;
    for (const CandidateRecord& c : plan.candidates) {
      moving = moving || c.state == CandidateState::kMoving;
      if ((!is_open(c.state) && c.state != CandidateState::kMoving) || c.custom) continue;
      open = true;
      p.best_gain_m2 =
          std::max(p.best_gain_m2, c.candidate.gain_unscanned_m2 + c.candidate.gain_low_res_m2);
    }
    // Places the plan ranked behind count while the robot can still go on: a plan whose every
    // suggestion was refused leads nowhere.
    if (open) p.best_left_m2 = std::max(p.best_left_m2, plan.best_gain_m2);
  }
  p.best_left_m2 = std::max(p.best_left_m2, p.best_gain_m2);
  if (finished) {
    p.state = "finished";
    p.finished_by = finished->first;
    p.finished_at = finished->second;
    return p;
  }
  if (after.empty()) {
    p.state = "running";
    return p;
  }
  if (p.best_left_m2 < p.threshold_m2 && !moving) {
    p.state = "complete";
    p.scans_left = 0;
    return p;
  }
  p.state = "running";
  // Each scan completes less than the one before (what is left lies farther apart, behind more
  // corners): the recent rate of that decline, carried on until the best scan would add less
  // than the threshold. Gains that do not decline give no estimate.
  std::vector<double> gains;
  for (std::size_t i = 1; i < after.size(); ++i) {
    gains.push_back(after[i].completed_m2 - after[i - 1].completed_m2);
  }
  const std::size_t k = std::min(gains.size(), static_cast<std::size_t>(config.recent_scans));
  if (k < 2) return p;
  const double first = std::max(gains[gains.size() - k], 1.0);
  const double last = std::max(gains.back(), 1.0);
  const double ratio = std::pow(last / first, 1.0 / static_cast<double>(k - 1));
  if (!(ratio < 0.98)) return p;
  const double decline = std::max(ratio, 0.5);
  p.scans_left = std::max(1, static_cast<int>(std::ceil(std::log(p.threshold_m2 / p.best_left_m2) /
                                                        std::log(decline))));
  return p;
}

}  // namespace scanplan::server
