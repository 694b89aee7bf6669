#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/mapping/mapping_pipeline.hpp"
#include "scanplan/mission/sensor_frame.hpp"
#include "scanplan/planning/fleet_planner.hpp"
#include "scanplan/planning/scan_planner.hpp"
#include "scanplan/registration/map_matcher.hpp"

namespace scanplan {

struct MissionConfig {
  // The segmentation's and the movable region's thresholds are the planner's
  // (planner.regions, planner.movable): mapping.regions and mapping.movable are not used.
  PipelineConfig mapping;
  PlannerConfig planner;
  // Scan matching of each new scan against the map so far (paper §4); nothing: scans go where
  // the robot says they are.
  std::optional<MapMatchConfig> matching = MapMatchConfig{};
  // How wrong a reported pose is, for carrying it into the map frame (SensorFrame).
  PoseSensorNoise pose_noise;
};

// Where a scan joins the map, and how it got there.
struct Placement {
  Pose reported;         // what the robot's pose sensors said (their frame)
  Pose placed;           // where the scan goes in the map frame
  bool matched = false;  // placed by a match the sanity check believed
};

// The paper's loop as one object (§3 steps 1–4 with §4's matching), used alike by the server
// and by the closed-loop simulation: a scan comes in with the pose the robot reports, is
// matched against the map so far (placed), joins the MLS map (mapped), the movable region and
// the C/M/U segmentation follow (segmented), and the next scan points are chosen (planned).
// Pure computation and not thread-safe: its owner serialises access.
class MissionPipeline {
 public:
  explicit MissionPipeline(MissionConfig config = {});

  // Placed: where scan `scan` (its own frame) goes, matched from its reported pose carried into
  // the map frame (prior(); a refused match leaves it there) against the points near it
  // (MapMatchConfig::target_radius_m) of the anchored scans: the first, which defines the map
  // frame, and those placed by a match the sanity check believed. A scan left unmatched is
  // metres off as often as not; matched against, it would pull every later scan near it off
  // with it. Nothing when matching is off or nothing is anchored yet. Changes nothing.
  std::optional<MapMatch> place(const PointCloud& scan, const Pose& reported) const;
  // place() in two steps, for an owner that matches without holding its lock: what the match
  // needs from the map (nothing when there is nothing to match against), then match_to_map.
  struct MatchInput {
    PointCloud map_points;
    MapMatchConfig config;
    Pose prior;  // the reported pose in the map frame: where the match starts
  };
  std::optional<MatchInput> match_input(const Pose& reported) const;
  // `reported` carried into the map frame by what the anchored scans say of the pose sensors'
  // frame (SensorFrame): where an unmatched scan is best placed.
  Pose prior(const Pose& reported) const { return sensor_frame_.to_map(reported); }

  // Mapped and segmented: the scan joins the map at `where.placed`; it is anchored when a
  // believed match placed it (see place(); the first scan is anchored regardless). Returns its
  // points in the map frame (coloured; grey where the scan had no colour), shared, never
  // copied again.
  std::shared_ptr<const PointCloud> add(const PointCloud& scan, const Placement& where);
  // The same with the points in the map frame already made (to_map_frame).
  void add(const PointCloud& scan, const Placement& where,
           std::shared_ptr<const PointCloud> in_map);
  static std::shared_ptr<const PointCloud> to_map_frame(const PointCloud& scan, const Pose& placed);

  // Planned: the next scan point for each robot (plan_fleet, PlanInput::claimed for `claimed`,
  // the goals of robots already driving). Empty before the first scan.
  std::vector<FleetPlan> plan(const std::vector<FleetRobot>& robots,
                              std::vector<Eigen::Vector3d> claimed = {}) const;
  // One robot standing at `robot` (x, y, floor z); `seed` for the policies that draw at random.
  Plan plan_from(const Eigen::Vector3d& robot, std::uint64_t seed) const;

  // New planner parameters; the segmentation and the movable region follow their thresholds.
  void set_planner(const PlannerConfig& planner);
  void set_target(TargetRegion target);

  // The map's points (map frame) within `radius_m` of (x, y) in the x-y plane; only the
  // anchored scans' when `anchored_only`.
  PointCloud points_near(double x, double y, double radius_m, bool anchored_only = false) const;
  // Whether the i-th scan (in the order they joined) is anchored (see place()).
  bool anchored(std::size_t i) const { return anchored_.at(i) != 0; }
  // Each scan's points in the map frame, in the order they joined.
  const std::vector<std::shared_ptr<const PointCloud>>& placed_scans() const { return placed_; }
  const MappingPipeline& mapping() const { return mapping_; }
  // The map of the anchored scans; nothing when matching is off.
  const MlsMap* anchored_map() const { return anchored_map_ ? &*anchored_map_ : nullptr; }
  const PlannerConfig& planner() const { return config_.planner; }
  const MissionConfig& config() const { return config_; }
  // Whether there is a map to plan on (a first scan, its regions and movable region).
  bool has_map() const;

 private:
  MissionConfig config_;
  MappingPipeline mapping_;
  std::vector<std::shared_ptr<const PointCloud>> placed_;
  std::vector<std::uint8_t> anchored_;  // per entry of placed_
  // The anchored scans alone, as the planner forecasts the matcher on them (PlanInput::anchored);
  // kept only while matching is on.
  std::optional<MlsMap> anchored_map_;
  SensorFrame sensor_frame_;
};

}  // namespace scanplan
