// Issue 17 on real data: the three 3DTK sample scans (a SICK scanner on a rotating mount, as the
// paper's) optimised jointly, every pair matched and the pose graph solved, as slam6D's global
// relaxation does, and compared with slam6D's own poses (`.reference`). The scans are not
// levelled: roll and pitch come from the reference, as an inclination sensor would give them
// (docs/benchmarks.md, "Real data"); x, y, z and yaw start from the odometry.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

#include "io/scan_file_test_support.hpp"
#include "scanplan/graph/pose_graph.hpp"
#include "scanplan/graph/relative_pose.hpp"
#include "scanplan/io/threedtk.hpp"
#include "scanplan/mission/scan_graph.hpp"
#include "scanplan/registration/registration.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;

struct Errors {
  double cm, deg;
};

// `estimate` against `truth`, both relative to scan 0.
Errors error_of(const Pose& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d e = truth.inverse() * estimate.isometry();
  return {100 * e.translation().norm(), rad2deg(Eigen::AngleAxisd(e.linear()).angle())};
}

struct Joint {
  std::array<Pose, 3> graph, chain;  // jointly optimised; pairwise 0→1→2 alone
  std::array<Eigen::Isometry3d, 3> reference;
  std::size_t outliers = 0;
};

Joint optimise_jointly() {
  const fs::path dir = test_support::threedtk_sample_dir();
  ThreedtkScanOptions cut;  // the scanner's mount and the saturation shell out
  cut.min_range_m = 0.3;
  cut.max_range_m = 32.0;
  Joint out;
  std::array<Pose, 3> start;
  std::array<PointCloud, 3> levelled_scans;
  for (int i = 0; i < 3; ++i) {
    const std::string stem = (dir / ("scan00" + std::to_string(i))).string();
    out.reference[i] = read_threedtk_reference(stem + ".reference");
    start[i] = Pose::from_isometry(read_threedtk_pose(stem + ".pose"));
    const Pose tilt = Pose::from_isometry(out.reference[i]);
    start[i].roll = tilt.roll;
    start[i].pitch = tilt.pitch;
    levelled_scans[i] = levelled(read_threedtk_scan(stem + ".3d", nullptr, cut), start[i]);
  }
  start[0] = Pose::from_isometry(out.reference[0]);  // scan000 is the origin
  PoseGraph graph;
  for (const Pose& p : start) graph.add_node(p);
  std::array<std::optional<RelativePose>, 3> pair;  // 0→1, 1→2, 0→2
  const std::array<std::pair<int, int>, 3> pairs = {{{0, 1}, {1, 2}, {0, 2}}};
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const auto [a, b] = pairs[e];
    const Pose from = level(start[a]), to = level(start[b]);
    const RegistrationResult r = register_scans(levelled_scans[a], levelled_scans[b],
                                                from.isometry().inverse() * to.isometry(),
                                                Method::kSearchGicp, RegistrationConfig{});
    EXPECT_TRUE(r.converged) << a << "→" << b << ": " << r.message;
    if (!r.converged) continue;
    pair[e] = relative_pose(from, r.transform);
    // As ScanGraph weighs a pairwise match: σ 3 cm a point-to-plane distance.
    graph.add_edge({static_cast<std::size_t>(a), static_cast<std::size_t>(b), *pair[e],
                    r.information / (0.03 * 0.03), EdgeKind::kMatch});
  }
  const GraphSolveReport report = graph.optimise();
  EXPECT_TRUE(report.solved) << report.message;
  out.outliers = report.outliers.size();
  for (int i = 0; i < 3; ++i) out.graph[i] = graph.pose(i);
  out.chain[0] = start[0];
  if (pair[0]) out.chain[1] = compose(out.chain[0], *pair[0], start[1].roll, start[1].pitch);
  if (pair[1]) out.chain[2] = compose(out.chain[1], *pair[1], start[2].roll, start[2].pitch);
  return out;
}

// What it measures (docs/benchmarks.md, "Real data"): in x-y and yaw the graph lands within
// 2.6 cm and 0.09° of slam6D's poses; in z 6.8–7.6 cm off, the floor of this room (seen tilted by
// 4° within 1.5 m of the scanner) leaving z to the estimator: ndt-icp's pairs end 5.6 and 0.5 cm
// off in z where search-gicp's end 6.8 and 7.6. The third edge (0→2, the loop) moves the scans
// 1.0 and 2.1 cm from the chain 0→1→2, and sets nothing aside.
TEST(ThreedtkJoint, ThreeRealScansOptimisedTogetherAgreeWithSlam6d) {
  if (!fs::exists(test_support::threedtk_sample_dir() / "scan000.3d")) {
    GTEST_SKIP() << "3DTK sample scans not found at " << test_support::threedtk_sample_dir();
  }
  const Joint j = optimise_jointly();
  EXPECT_EQ(j.outliers, 0u) << "three matches of one room agree";
  for (int i = 1; i < 3; ++i) {
    const Eigen::Isometry3d truth = j.reference[0].inverse() * j.reference[i];
    const Errors graph = error_of(j.graph[i], truth), chain = error_of(j.chain[i], truth);
    const Eigen::Vector3d d = j.graph[i].isometry().translation() - truth.translation();
    EXPECT_LT(std::hypot(d.x(), d.y()), 0.03) << "scan " << i;
    EXPECT_LT(std::abs(d.z()), 0.08) << "scan " << i;
    EXPECT_LT(graph.deg, 0.2) << "scan " << i;
    const Eigen::Vector3d apart =
        j.graph[i].isometry().translation() - j.chain[i].isometry().translation();
    EXPECT_LT(apart.norm(), 0.03) << "scan " << i << ": the loop edge agrees with the chain";
    const std::string name = "scan00" + std::to_string(i);
    RecordProperty(name + "_graph_xy_cm", std::to_string(100 * std::hypot(d.x(), d.y())));
    RecordProperty(name + "_graph_z_cm", std::to_string(100 * d.z()));
    RecordProperty(name + "_graph_deg", std::to_string(graph.deg));
    RecordProperty(name + "_chain_cm", std::to_string(chain.cm));
  }
}

}  // namespace
}  // namespace scanplan
