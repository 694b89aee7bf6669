#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/mapping/mapping_pipeline.hpp"
#include "scanplan/mission/placement.hpp"
#include "scanplan/mission/scan_graph.hpp"
#include "scanplan/mission/sensor_frame.hpp"
#include "scanplan/mission/view_check.hpp"
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
  // How wrong a reported pose is: for carrying it into the map frame (SensorFrame) and for
  // weighing the robot's odometry in the pose graph.
  PoseNoise pose_noise;
  // The pose graph over the scans (issue 17), used while matching is on; nothing: each scan
  // stays where its match to the map put it.
  std::optional<ScanGraphConfig> graph = ScanGraphConfig{};
  // When the graph moves a scan farther than this, its points are made anew in the map frame
  // (placed_scans(); what the operator sees and the owner re-sends).
  double replace_m = 0.02;
  double replace_deg = 0.05;
  // When the graph moves a scan in the MLS map farther than this, the map is made anew where the
  // scan lay and lies (the map's cells are 1 m, the movable region's steps 15 cm: a smaller
  // correction changes nothing the planner sees, and a long session's map took seconds to make
  // anew for 2 cm moves; issue 19).
  double remap_m = 0.05;
  double remap_deg = 0.1;
  // The best candidates of each plan checked against the anchored map's points (issue 15);
  // only while matching is on.
  ViewCheckConfig view_check;
};

// How the map changed when the graph moved scans after the latest one joined.
struct MapCorrection {
  GraphUpdate graph;
  // The scans (in joining order) whose pose (the graph's estimate, poses()) moved more than
  // 5 mm or 0.01°; their points and the MLS map follow past MissionConfig::replace_m and remap_m,
  // so smaller moves wait until they add up.
  std::vector<std::size_t> moved;
  double max_moved_m = 0, max_turned_deg = 0;
  // How long the graph took over the scan (wall clock): its pairs, the refused scans matched
  // again, the solve.
  double graph_ms = 0;
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
  // frame, and those placed by a match the sanity check believed; of scans taken within a
  // metre of each other, the latest alone (the same surfaces twice cost time, and a long
  // session's passes over one site made the match grow with it). A scan left unmatched is
  // metres off as often as not; matched against, it would pull every later scan near it off
  // with it. Nothing when matching is off or nothing is anchored yet. Changes nothing.
  // `driven_m`: the path the robot was sent along since its previous scan (Placement::driven_m).
  std::optional<MapMatch> place(const PointCloud& scan, const Pose& reported,
                                const std::string& track = {}, double driven_m = 0) const;
  // place() in two steps, for an owner that matches without holding its lock: what the match
  // of `scan` needs from the map (nothing when there is nothing to match against), then
  // match_to_map.
  struct MatchInput {
    PointCloud map_points;
    // Its lengths already sized by the scan (RegistrationConfig::adapt_to_scene done).
    MapMatchConfig config;
    Pose prior;        // the reported pose in the map frame: where the match starts
    MatchViews views;  // where map_points were seen from, and the new scan's scanner
  };
  std::optional<MatchInput> match_input(const PointCloud& scan, const Pose& reported,
                                        const std::string& track = {}, double driven_m = 0) const;
  // `reported` carried into the map frame by what the anchored scans say of the pose sensors'
  // frame (SensorFrame): where an unmatched scan is best placed.
  // With drifting odometry and the graph on, the robot's latest scan as the graph has it,
  // moved by what its odometry reports since (`track`: the robot id).
  Pose prior(const Pose& reported, const std::string& track = {}) const;

  // Mapped and segmented: the scan joins the map at `where.placed`; it is anchored when a
  // believed match placed it (see place(); the first scan is anchored regardless). Returns its
  // points in the map frame (coloured; grey where the scan had no colour), shared, never
  // copied again. With the graph on, the scan is then matched with its neighbours and the graph
  // optimised; where that moves scans, the map follows (last_correction()), and the points
  // returned are where the scan lay when it joined.
  std::shared_ptr<const PointCloud> add(const PointCloud& scan, const Placement& where);
  // The same with the points in the map frame already made (to_map_frame).
  void add(const PointCloud& scan, const Placement& where,
           std::shared_ptr<const PointCloud> in_map);
  static std::shared_ptr<const PointCloud> to_map_frame(const PointCloud& scan, const Pose& placed);

  // Planned: the next scan point for each robot (plan_fleet, PlanInput::claimed for `claimed`,
  // the goals of robots already driving; with drifting odometry each robot's drift_of its id).
  // Empty before the first scan.
  std::vector<FleetPlan> plan(const std::vector<FleetRobot>& robots,
                              std::vector<Eigen::Vector3d> claimed = {}) const;
  // One robot standing at `robot` (x, y, floor z), scanning as `track`; `seed` for the policies
  // that draw at random.
  Plan plan_from(const Eigen::Vector3d& robot, std::uint64_t seed,
                 const std::string& track = {}) const;
  // With the graph on drifting odometry: how uncertain `track`'s pose is after its latest scan
  // (nothing when the map placed that scan) and how it grows as the robot drives
  // (PlanInput::drift). Nothing otherwise, or before the track's first scan.
  std::optional<DriveDrift> drift_of(const std::string& track) const;
  // What the planner counts as scanned although the map does not hold it: each scan outside the
  // map, at the graph's estimate and where its robot was sent for it (Placement::goal).
  std::vector<Eigen::Vector3d> unplaced_scan_points() const;

  // New planner parameters; the segmentation and the movable region follow their thresholds.
  void set_planner(const PlannerConfig& planner);
  void set_target(TargetRegion target);

  // The map's points (map frame) within `radius_m` of (x, y) in the x-y plane; only the
  // anchored scans' when `anchored_only`. With `views`, where each was seen from.
  PointCloud points_near(double x, double y, double radius_m, bool anchored_only = false,
                         Viewpoints* views = nullptr) const;
  // Where the scanner sits in a scan's own frame (PipelineConfig::sensor_height_m above its
  // origin). Also taken for a scan levelled by its tilt: that moves it a few centimetres, and
  // which way a surface faces from it not at all.
  Viewpoints scanner_view() const;
  // Whether the i-th scan (in the order they joined) is anchored (see place(); with the graph,
  // whether believed matches tie it to the first scan).
  bool anchored(std::size_t i) const { return anchored_.at(i) != 0; }
  // Each scan's pose in the map, in joining order (the graph's latest estimate).
  const std::vector<Pose>& poses() const { return poses_; }
  // Whether the i-th scan is in the MLS map (mapping()): with the graph on, only anchored
  // scans are, so that one left metres off makes no phantom walls and steps for the planner;
  // it joins once a match ties it in.
  bool in_map(std::size_t i) const { return in_map_.at(i) != 0; }
  // Why the i-th scan is not in the map (ScanGraph::outside_reason); empty when it is.
  std::string outside_reason(std::size_t i) const;
  // What the graph did after the latest scan; nothing with the graph off.
  const std::optional<MapCorrection>& last_correction() const { return last_correction_; }
  const ScanGraph* graph() const { return graph_ ? &*graph_ : nullptr; }
  // Each scan's points in the map frame, in the order they joined, at cloud_poses(): the
  // graph's estimate (poses()) moves them anew only past MissionConfig::replace_m / _deg.
  const std::vector<std::shared_ptr<const PointCloud>>& placed_scans() const { return placed_; }
  const std::vector<Pose>& cloud_poses() const { return cloud_poses_; }
  // Where the MLS map holds each scan (in_map()): the graph's estimate when it last moved past
  // MissionConfig::remap_m / _deg; its points moved there from cloud_poses().
  const std::vector<Pose>& map_poses() const { return map_poses_; }
  // The scans in the MLS map in the order they entered it (a scan anchored late enters after the
  // ones already there): the map is what they make from scratch in that order.
  const std::vector<std::size_t>& map_order() const { return map_order_; }
  // The i-th scan's points at the graph's estimate (a copy).
  PointCloud at_estimate(std::size_t i) const;
  const MappingPipeline& mapping() const { return mapping_; }
  // The map of the anchored scans (with the graph on, mapping()'s); nothing when matching is
  // off.
  const MlsMap* anchored_map() const {
    if (graph_) return &mapping_.map();  // it holds the anchored scans alone
    return anchored_map_ ? &*anchored_map_ : nullptr;
  }
  const PlannerConfig& planner() const { return config_.planner; }
  // planner() as the plans use it: from absolute fixes too rough to place a scan by themselves,
  // a candidate's walls must fix the pose more firmly (RegistrabilityConfig::absolute_fix_factor).
  PlannerConfig planner_config() const;
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
  std::vector<Pose> reported_;     // per scan, for refitting sensor_frame_
  std::vector<Pose> poses_;        // per scan: where it is (the graph's estimate)
  std::vector<Pose> cloud_poses_;  // per scan: the pose its placed_ points were put at
  std::vector<Pose> map_poses_;    // per scan: where the MLS map holds it
  std::vector<std::size_t> map_order_;
  std::vector<Bounds3> cloud_bounds_;  // per scan: its placed_ points' bounds
  std::vector<std::uint8_t> in_map_;
  std::vector<std::optional<Eigen::Vector3d>> goals_;  // per scan: Placement::goal
  std::optional<ScanGraph> graph_;
  std::optional<MapCorrection> last_correction_;
  // Per scan: how many anchored scans lay near it when it was last matched to the map; it is
  // tried again when more do.
  std::vector<std::size_t> anchored_near_;
  // Each robot's planner evaluations, reused from one of its plans to the next (GainMemo).
  struct Memos {
    std::mutex mutex;
    std::map<std::string, std::unique_ptr<GainMemo>> by_robot;
    GainMemo* of(const std::string& robot);
  };
  std::shared_ptr<Memos> memos_ = std::make_shared<Memos>();

  // The pose sensors place a scan closely enough by themselves when 3σ of their error is
  // within this: the accuracy the map is built to (issue 17's target).
  static constexpr double kSensorsPlaceM = 0.05;
  static constexpr double kSensorsPlaceDeg = 0.1;
  // Two scans taken this close see the same surfaces from the same spot (match_sources).
  static constexpr double kSameViewM = 1.0;
  struct SensorFix {
    std::size_t from = 0;  // the scan the sensors relate it to
    Eigen::Matrix4d information;
  };
  std::optional<SensorFix> sensors_place(const Placement& where) const;
  bool rematch_refused(GraphUpdate& update);
  bool unsure(const Placement& where) const;
  bool beyond_reach(const MoveUncertainty& u) const;
  void follow_graph();
  bool cloud_lags(std::size_t i) const;
  bool map_lags(std::size_t i) const;
  MappingPipeline::PlacedScan as_mapped(std::size_t i) const;
  Eigen::Affine3f lag_of(std::size_t i) const;
  void join_map(std::size_t i);
  bool reaches(std::size_t i, double x, double y, double radius_m) const;
  std::vector<std::size_t> match_sources(double x, double y, double radius_m) const;
  PointCloud points_of(const std::vector<std::size_t>& scans, double x, double y, double radius_m,
                       Viewpoints* views, double thinned_to_m = 0) const;
  void set_cloud(std::size_t i, std::shared_ptr<const PointCloud> in_map);
  // The weakest constraint a scan at `candidate` is predicted to meet (ViewCheckConfig), and
  // the plan's best candidates checked by it.
  double predicted_constraint(const Candidate& candidate) const;
  void check_plan(Plan& plan) const;
  MapCorrection correction(const GraphUpdate& update, const std::vector<Pose>& before) const;
  void replace();
};

}  // namespace scanplan
