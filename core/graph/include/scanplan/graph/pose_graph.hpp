#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/graph/relative_pose.hpp"

namespace scanplan {

enum class EdgeKind {
  kOdometry,  // the robot's own account of a move between two of its scans
  kMatch,     // two scans (or a scan and the map) matched
};

// One relation between two scans: `to` seen from `from` (relative_pose), and how sure it is.
struct GraphEdge {
  std::size_t from = 0, to = 0;
  RelativePose measured;
  // The inverse covariance of (x, y, z, yaw) in metres and radians; symmetric positive definite.
  Eigen::Matrix4d information = Eigen::Matrix4d::Identity();
  EdgeKind kind = EdgeKind::kMatch;
};

struct PoseGraphConfig {
  // Match edges carry a Cauchy loss of this scale, in standard deviations (whitened residual):
  // an edge this far off weighs half as much as a quadratic cost would, one ten times as far
  // almost nothing, so one wrong match cannot bend the map. Odometry edges are never wrong in
  // that way (their error is already as wide as the drift) and stay quadratic.
  double robust_scale = 3.0;
  int max_iterations = 100;
  // An edge whose whitened residual ends above this is reported as an outlier.
  double outlier_sigma = 5.0;
};

struct GraphSolveReport {
  bool solved = false;  // Ceres ended on a convergence criterion (or had nothing to do)
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  double time_ms = 0;
  std::vector<std::size_t> outliers;  // indices into edges()
  std::string message;                // Ceres' brief report
};

// The scans' poses as a graph in the four parameters matching adjusts (x, y, z, yaw; roll and
// pitch stay as measured), optimised with Ceres (DESIGN.md: libceres-dev). Node 0, the first
// scan, defines the map frame and is held fixed. Pure computation, not thread-safe.
class PoseGraph {
 public:
  explicit PoseGraph(PoseGraphConfig config = {}) : config_(config) {}

  // A new scan at its current estimate; returns its index.
  std::size_t add_node(const Pose& estimate);
  // Throws std::invalid_argument for an index not yet added, a self-loop, or an information
  // matrix that is not symmetric positive definite.
  void add_edge(const GraphEdge& edge);
  // Sets one node's estimate (e.g. a better start before the next solve).
  void set_pose(std::size_t node, const Pose& estimate);
  // Sets what an edge measured and how surely (e.g. an absolute fix carried into a frame
  // estimated anew); throws as add_edge does.
  void set_measurement(std::size_t edge, const RelativePose& measured,
                       const Eigen::Matrix4d& information);

  // Moves every node but the first to the poses that best agree with all edges.
  GraphSolveReport optimise();

  std::size_t size() const { return poses_.size(); }
  const Pose& pose(std::size_t node) const { return poses_.at(node); }
  const std::vector<Pose>& poses() const { return poses_; }
  const std::vector<GraphEdge>& edges() const { return edges_; }
  // The edge's residual at the current poses, whitened by its information: √(rᵀ Ω r).
  double whitened_error(std::size_t edge) const;

 private:
  PoseGraphConfig config_;
  std::vector<Pose> poses_;
  std::vector<GraphEdge> edges_;
};

}  // namespace scanplan
