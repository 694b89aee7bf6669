#include "scanplan/planning/fleet_planner.hpp"

#include <limits>
#include <optional>
#include <stdexcept>

namespace scanplan {

std::vector<FleetPlan> plan_fleet(const MlsMap& map, const TargetRegion& target,
                                  const std::vector<Eigen::Vector2d>& scan_points,
                                  const std::vector<FleetRobot>& robots,
                                  std::vector<Eigen::Vector3d> claimed, const PlannerConfig& cfg,
                                  const MlsMap* anchored) {
  if (!(cfg.fleet_tie_share >= 0 && cfg.fleet_tie_share < 1)) {
    throw std::invalid_argument("planner config: fleet_tie_share must be in [0, 1)");
  }
  std::vector<FleetPlan> decided;
  std::vector<FleetRobot> open = robots;
  for (bool first_turn = true; !open.empty(); first_turn = false) {
    std::vector<Plan> plans;
    plans.reserve(open.size());
    for (const FleetRobot& r : open) {
      // The other robots stand where they are until they are sent somewhere.
      std::vector<Eigen::Vector3d> others;
      for (const FleetRobot& o : robots) {
        if (o.id != r.id) others.push_back(o.position);
      }
      PlanInput in{map, target, scan_points, r.position};
      in.claimed = &claimed;
      in.occupied = &others;
      in.anchored = anchored;
      in.drift = r.drift ? &*r.drift : nullptr;
      in.refused = &r.refused;
      if (first_turn) in.memo = r.memo;
      plans.push_back(plan_next_scan(in, cfg));
    }
    // The highest best score; then, among those close to it, the shortest drive.
    double top = -std::numeric_limits<double>::infinity();
    for (const Plan& p : plans) {
      if (!p.ranked.empty()) top = std::max(top, p.ranked.front().score);
    }
    std::optional<std::size_t> pick;
    for (std::size_t k = 0; k < plans.size(); ++k) {
      if (plans[k].ranked.empty()) continue;
      const Candidate& best = plans[k].ranked.front();
      if (best.score < top - cfg.fleet_tie_share * std::abs(top)) continue;
      if (!pick || best.travel_m < plans[*pick].ranked.front().travel_m) pick = k;
    }
    if (!pick) {
      // Nothing worth scanning for anyone left: their (empty) plans as they are.
      for (std::size_t k = 0; k < open.size(); ++k) {
        decided.push_back({open[k].id, std::move(plans[k])});
      }
      break;
    }
    claimed.push_back(plans[*pick].ranked.front().position);
    decided.push_back({open[*pick].id, std::move(plans[*pick])});
    open.erase(open.begin() + static_cast<std::ptrdiff_t>(*pick));
  }
  return decided;
}

}  // namespace scanplan
