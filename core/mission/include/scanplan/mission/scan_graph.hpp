#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose_noise.hpp"
#include "scanplan/graph/pose_graph.hpp"
#include "scanplan/mission/move_uncertainty.hpp"
#include "scanplan/mission/placement.hpp"
#include "scanplan/mission/sensor_frame.hpp"
#include "scanplan/registration/registration.hpp"

namespace scanplan {

// Pairwise matching's configuration: the defaults, with the lengths sized by
// RegistrationConfig::range_by_direction as the map match's are.
RegistrationConfig pair_registration();

struct ScanGraphConfig {
  PoseGraphConfig solver;
  // Pairwise matches (only where one scan of the pair is not in the map: match_pairs) with the
  // earlier scans whose positions lie within this (x-y), the nearest first, at most max_pairs of
  // them: pairs farther apart than the scanner's useful range share too little to be worth the
  // time (the planner spaces scans 30–40 m).
  double pair_radius_m = 45.0;
  std::size_t max_pairs = 6;
  // Pairwise matches and re-matches of refused scans made at once, one a thread (0: the OpenMP
  // default, the cores). Each is tens of milliseconds of work, so a loaded core delays it
  // without the barrier costs of a finer split; the graph is the same on any count.
  int threads = 0;
  // The pairwise match: the search over how far off the scan not anchored may be, then GICP
  // (search-gicp), on the scans thinned and levelled, its lengths sized from how far each scan
  // sees where its view is open (RegistrationConfig::range_by_direction).
  RegistrationConfig registration = pair_registration();
  // A pairwise result farther than this from where the graph had the pair is not believed
  // however far the search looked (see widened()): the pose sensors' usual reach
  // (MapMatchConfig::max_correction_m).
  double max_search_shift_m = 6.0;
  double max_search_turn_deg = 25.0;
  // Two pairwise matches agree on where a scan lies when their results are this close.
  double agree_m = 0.10;
  double agree_deg = 0.2;
  // σ of one point-to-plane distance in a match (the scanner's range noise is 1 cm):
  // AlignmentQuality::information / σ² is a match edge's information.
  double match_sigma_m = 0.01;
  // A pairwise match sees one scan where the map match saw all of them around: less overlap,
  // and its errors are larger (on the campus loop: 1–7 cm where the map match's are 1 cm).
  double pair_sigma_m = 0.03;
  // Odometry edges: a drive around what is in the way is longer than the straight line between
  // the two reports, and the drift grows with the path (DESIGN.md: 2 % of the distance driven).
  // Where the path the robot was sent along is known (Placement::driven_m) and longer, it counts.
  double path_factor = 1.5;
  // Odometry edges are never surer than this (a robot that did not move still slips).
  double min_odometry_sigma_m = 0.05;
  double min_odometry_sigma_deg = 0.05;
};

// `pose` without its tilt: the levelled frame at it (x, y, z, yaw; z vertical).
Pose level(Pose pose);
// `scan` (its own frame at `pose`) in the levelled frame at `pose`: the 4-DOF solver then turns
// about the true vertical, and a transform between two levelled scans is their relative pose
// (relative_pose) as it stands. Matched in their tilted own frames, two scans on sloping
// ground turn about a tilted axis and their relative yaw comes out biased.
PointCloud levelled(PointCloud scan, const Pose& pose);

// `config` whose search reaches 3σ of `prior` where that is wider than it already is
// (scan-to-map matching and the pairwise search alike): a robot that drove 150 m on 2 %
// odometry may be 9 m off. Widened, the search looks at more peaks and refuses a fit that
// another distinct pose matches almost as well (PoseSearchConfig::ambiguity_ratio): the wider
// the search, the likelier it spans a repeated structure, and a match that another pose farther
// out fits as well is not believed. It never reaches beyond kWidestSearchM / _Deg. A map match
// that corrects beyond the sensors' usual reach waits for confirmation
// (ScanGraph::offer_match_to_map); a pairwise one is refused (max_search_shift_m). Always,
// narrow or widened, the search is told `prior` (PoseSearchConfig::prior_sigma_xy_m): of two
// fits, the one nearer where the odometry puts the scan comes first. A result the surfaces fix
// only weakly is believed on restarts (RegistrationConfig::restart_max_shift_m) up to 4σ of
// `prior` from its start.
inline constexpr double kWidestSearchM = 20.0;
inline constexpr double kWidestSearchDeg = 45.0;
RegistrationConfig widened(RegistrationConfig config, const MoveUncertainty& prior);

// What the graph did when one scan joined.
struct GraphUpdate {
  std::size_t pairs_tried = 0, pairs_matched = 0;
  double match_ms = 0;  // the pairwise matches together
  // Scans refused when they came and matched to the map again as it grew: tried, and matched
  // (tied in, or waiting for the robot's neighbouring scan to agree).
  std::size_t rematches_tried = 0, rematched = 0;
  GraphSolveReport solve;
};

// The scans of a mission as a pose graph (issue 17): the robot's odometry between its
// consecutive scans (or, for absolute fixes, each scan's fix in the map frame), each believed
// scan-to-map match, and pairwise matches between every two scans near each other (so a scan that
// could not be matched when it came is tied in by later ones, and a robot coming back near old
// scans closes the loop), optimised after every scan. Keeps each scan thinned and levelled for the
// pairwise matches. Not thread-safe.
class ScanGraph {
 public:
  ScanGraph(ScanGraphConfig config, PoseNoise noise);

  // Scan `scan` (own frame) joins at `where`; its pairs are matched and the graph optimised.
  // `tentative`: where.matched, but the match corrected the pose further than the sensors
  // usually err; it ties the scan in once the odometry to the robot's next or previous scan
  // agrees (confirm_by_odometry). `scanner`: where the scanner sits in the scan's frame, for
  // telling the faces of thin surfaces apart in pairwise matches (unknown: not told apart).
  GraphUpdate add(const PointCloud& scan, const Placement& where, bool tentative = false,
                  const Viewpoints& scanner = {});
  // A scan not anchored so far was matched to the map after all (MapMatch::placed and
  // ::information): it is tied to the anchored scan nearest to where the match put it. Call
  // solve() after.
  void add_match_to_map(std::size_t scan, const Pose& placed, const Eigen::Matrix4d& information,
                        const char* origin = "rematch");
  // A map match of a scan whose estimate may be off by more than the sensors' usual reach (a
  // far correction, or a prior after long drives with nothing anchored): it waits until the
  // robot's scan before or after, matched the same way, or the one after placed by its own
  // match, lies where the odometry between the two says (confirm_by_odometry), or until a
  // pairwise match with a later scan in the map puts it where the map match did
  // (later_pair_confirms). Call solve() after.
  void offer_match_to_map(std::size_t scan, const Pose& placed, const Eigen::Matrix4d& information);
  // The pose sensors alone place scan `scan` closely enough (MissionPipeline::sensors_place):
  // it is tied to scan `from` (the first scan for an absolute fix, the robot's last anchored
  // scan for a short drive on odometry) by what the sensors reported, with their information.
  // Call solve() after.
  void anchor_by_sensors(std::size_t scan, std::size_t from, const Eigen::Matrix4d& information);
  // Absolute fixes (OdometryModel::kAbsolute): where the pose sensors' frame lies in the map
  // frame, as the anchored scans now measure it (MissionPipeline's SensorFrame). Every scan's
  // fix edge is carried into the map frame by it, the next scan's too. Call solve() after (or
  // add()).
  void set_sensor_frame(const SensorFrame& frame);
  GraphSolveReport solve();

  std::size_t size() const { return graph_.size(); }
  const std::vector<Pose>& poses() const { return graph_.poses(); }
  // Whether the scan is tied into the map: the first, one a believed map match placed (when it
  // came or later), or one two agreeing pairwise matches with anchored scans placed; and the
  // edge that did it not set aside as an outlier.
  bool anchored(std::size_t scan) const { return anchored_.at(scan) != 0; }
  // Why a scan is not anchored, for whoever reads why it is not in the map (empty when it is
  // anchored): a far map match waiting for the robot's next scan to agree (and how far it lies
  // from where the odometry puts the scan), pairwise matches waiting for a second, or none.
  std::string outside_reason(std::size_t scan) const;
  // The latest scan of a robot, if any.
  std::optional<std::size_t> last_of(const std::string& track) const;
  // The latest scan of a robot that is anchored, if any.
  std::optional<std::size_t> last_anchored_of(const std::string& track) const;
  // How wrong odometry over `move` (reported poses) may be, by the noise model; `driven_m`: the
  // path driven, when known (0: path_factor times the straight line).
  MoveUncertainty odometry_uncertainty(const RelativePose& move, double driven_m = 0) const;
  // How wrong a pose carried by odometry from the robot's latest anchored scan to `reported`
  // may be: the error of each move since, one after the other (a heading error swinging the
  // moves after it); `driven_m` is the last move's path (Placement::driven_m). Nothing for a
  // robot's first scan or absolute fixes.
  std::optional<MoveUncertainty> prior_uncertainty(const std::string& track, const Pose& reported,
                                                   double driven_m = 0) const;
  const Pose& reported(std::size_t scan) const { return reported_.at(scan); }
  // The scan levelled at its pose (levelled()), thinned as matching thins it.
  const PointCloud& thinned(std::size_t scan) const { return *thinned_.at(scan); }
  // The voxel it was thinned to (RegistrationConfig::voxel_m sized by the scan's own range).
  double thinned_voxel_m(std::size_t scan) const { return thinned_voxel_.at(scan); }
  // How far off the scan's estimate may be while no believed match ties it in (zero once one
  // does).
  const MoveUncertainty& uncertainty(std::size_t scan) const { return uncertain_.at(scan); }
  const PoseGraph& graph() const { return graph_; }
  // How each edge of graph() came about, by index: "odometry", "fix" (an absolute fix),
  // "pair-search" (a pairwise match, the search first: one end was not anchored), "map" (a
  // scan-to-map match when the scan came), "map-confirmed" (one beyond the sensors' reach,
  // confirmed by the odometry to the robot's next or previous scan or by a pairwise match with a
  // later scan in the map), "rematch" (one later),
  // "sensors" (anchor_by_sensors).
  const std::string& edge_origin(std::size_t edge) const { return origins_.at(edge); }
  const ScanGraphConfig& config() const { return config_; }

 private:
  void add_odometry(std::size_t from, std::size_t to);
  void add_fix(std::size_t scan);
  std::pair<RelativePose, Eigen::Matrix4d> fix_of(std::size_t scan) const;
  void match_pairs(std::size_t scan, bool matched_to_map, GraphUpdate& update);
  // What a pairwise match starts from: both ends levelled where they likeliest lie, and how far
  // off that may be.
  struct PairStart {
    Pose from, to;
    MoveUncertainty uncertainty;
    bool operator==(const PairStart&) const = default;
  };
  PairStart pair_start(std::size_t from, std::size_t to) const;
  std::optional<GraphEdge> match_pair(std::size_t from, std::size_t to,
                                      const PairStart& start) const;
  MoveUncertainty relative_uncertainty(std::size_t from, std::size_t to) const;
  void update_anchors(const GraphSolveReport& solve);
  static constexpr std::size_t kNoNode = static_cast<std::size_t>(-1);
  void add_match_edge(const GraphEdge& edge, const char* origin, std::size_t anchors);
  void offer(const GraphEdge& edge, std::size_t scan);
  bool odometry_agrees(std::size_t a, const Pose& a_placed, std::size_t b,
                       const Pose& b_placed) const;
  void confirm_by_odometry(std::size_t scan);
  // Scans no match placed that a confirmation by odometry reaches across (waiting_before).
  static constexpr std::size_t kMaxSkipped = 2;
  std::size_t waiting_before(std::size_t scan) const;
  double driven_between(std::size_t from, std::size_t to) const;
  bool agree(const Pose& a, const Pose& b) const;
  bool later_pair_confirms(std::size_t scan, const GraphEdge& edge) const;
  bool confirm_waiting(const GraphSolveReport& solve);
  void believe_waiting(std::size_t scan);
  // A map match: where it placed the scan, and the anchored scan nearest to that (`reference`)
  // where the map had it when the match ran.
  struct MapCandidate {
    Pose placed;
    Eigen::Matrix4d information;
    std::size_t reference;
    Pose reference_pose;
  };
  std::optional<MapCandidate> as_found(std::size_t scan, const Pose& placed,
                                       const Eigen::Matrix4d& information) const;
  Pose placed_now(std::size_t scan, const MapCandidate& match) const;
  Pose likeliest(std::size_t scan) const;
  void tie_to_map(std::size_t scan, const MapCandidate& match, const char* origin);
  Pose implied(const GraphEdge& edge, std::size_t scan) const;

  ScanGraphConfig config_;
  PoseNoise noise_;
  PoseGraph graph_;
  std::vector<std::shared_ptr<const PointCloud>> thinned_;  // levelled, per scan
  std::vector<double> thinned_voxel_;                       // per scan
  std::vector<Viewpoints> scanners_;                        // per scan, as add() was told
  std::vector<Pose> reported_;
  std::vector<double> driven_;  // per scan: Placement::driven_m, the drive that led to it
  std::vector<std::uint8_t> anchored_;
  std::vector<MoveUncertainty> uncertain_;  // per scan: of its estimate while not anchored
  std::map<std::string, std::size_t> last_of_track_;
  std::vector<std::string> origins_;  // per edge
  std::vector<std::size_t> anchors_;  // per edge: the scan it ties into the map, or kNoNode
  // Per scan not anchored: pairwise results with anchored scans waiting for one that agrees.
  std::vector<std::vector<GraphEdge>> pending_;
  // Per scan: a map match beyond the sensors' usual reach, waiting for the odometry to agree.
  std::vector<std::optional<MapCandidate>> pending_map_;
  std::vector<std::size_t> previous_;   // per scan: the robot's scan before it, or kNoNode
  std::vector<std::string> tracks_;     // per scan
  SensorFrame frame_;                   // absolute fixes: the sensors' frame in the map frame
  std::vector<std::size_t> fix_edges_;  // absolute fixes: the fix edge of scan 1, 2, …
};

}  // namespace scanplan
