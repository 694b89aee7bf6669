#include "scanplan/graph/pose_graph.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace scanplan {
namespace {

Pose pose(double x, double y, double z, double yaw_deg, double roll = 0, double pitch = 0) {
  Pose p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.yaw = deg2rad(yaw_deg);
  p.roll = roll;
  p.pitch = pitch;
  return p;
}

TEST(RelativePose, ComposeUndoesRelative) {
  const Pose a = pose(3, -2, 1, 170, 0.02, -0.01), b = pose(-20, 14, 2.5, -160, -0.03, 0.04);
  const RelativePose r = relative_pose(a, b);
  EXPECT_NEAR(r.yaw, deg2rad(30), 1e-12);  // across ±180°
  const Pose back = compose(a, r, b.roll, b.pitch);
  EXPECT_NEAR(back.x, b.x, 1e-12);
  EXPECT_NEAR(back.y, b.y, 1e-12);
  EXPECT_NEAR(back.z, b.z, 1e-12);
  EXPECT_NEAR(std::remainder(back.yaw - b.yaw, 2 * M_PI), 0, 1e-12);
}

// A match's 6-DOF transform (b's scan frame into a's) gives the same relative pose as the two
// poses do, whatever a's position and yaw: only its measured tilt matters.
TEST(RelativePose, FromATransformDependsOnTheTiltAlone) {
  const Pose a = pose(3, -2, 1, 170, 0.05, -0.04), b = pose(-20, 14, 2.5, -160, -0.03, 0.04);
  const Eigen::Isometry3d a_b = a.isometry().inverse() * b.isometry();
  const RelativePose r = relative_pose(a, b), m = relative_pose(a, a_b);
  EXPECT_NEAR(m.x, r.x, 1e-9);
  EXPECT_NEAR(m.y, r.y, 1e-9);
  EXPECT_NEAR(m.z, r.z, 1e-9);
  EXPECT_NEAR(m.yaw, r.yaw, 1e-9);
  Pose moved = a;
  moved.x += 40;
  moved.yaw += 1.0;
  const RelativePose again = relative_pose(moved, a_b);
  EXPECT_NEAR(again.x, r.x, 1e-9);
  EXPECT_NEAR(again.yaw, r.yaw, 1e-9);
}

Eigen::Matrix4d information(double sigma_m, double sigma_deg) {
  Eigen::Vector4d s(sigma_m, sigma_m, sigma_m, deg2rad(sigma_deg));
  return s.cwiseInverse().cwiseAbs2().asDiagonal();
}

GraphEdge edge(const std::vector<Pose>& truth, std::size_t from, std::size_t to, double sigma_m,
               double sigma_deg, EdgeKind kind, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  RelativePose r = relative_pose(truth[from], truth[to]);
  r.x += sigma_m * n(rng);
  r.y += sigma_m * n(rng);
  r.z += sigma_m * n(rng);
  r.yaw += deg2rad(sigma_deg) * n(rng);
  return {from, to, r, information(sigma_m, sigma_deg), kind};
}

// A square drive of 160 m, 16 scans 10 m apart, back to the start.
std::vector<Pose> square() {
  std::vector<Pose> truth;
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < 4; ++k) {
      const double along = 10.0 * k - 20.0;
      const double yaw = 90.0 * side;
      const double c = std::cos(deg2rad(yaw)), s = std::sin(deg2rad(yaw));
      // Side 0 runs along +x at y = −20, and so on counter-clockwise.
      truth.push_back(pose(c * along + s * 20.0, s * along - c * 20.0, 0.1 * k, yaw));
    }
  }
  return truth;
}

double error_m(const Pose& a, const Pose& b) {
  return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z);
}

// Chained matches, each a few centimetres and a tenth of a degree off, drift; one match of the
// last scan back to the first closes the loop and brings every scan within centimetres.
TEST(PoseGraph, LoopClosureUndoesChainedDrift) {
  const std::vector<Pose> truth = square();
  std::mt19937_64 rng(7);
  PoseGraph graph;
  graph.add_node(truth[0]);
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const GraphEdge chain = edge(truth, i - 1, i, 0.03, 0.15, EdgeKind::kMatch, rng);
    graph.add_node(compose(graph.pose(i - 1), chain.measured, 0, 0));
    graph.add_edge(chain);
  }
  double chained_worst = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    chained_worst = std::max(chained_worst, error_m(graph.pose(i), truth[i]));
  }
  const double drift = error_m(graph.pose(truth.size() - 1), truth.back());
  EXPECT_GT(drift, 0.10) << "the chain should drift for the test to mean anything";

  graph.add_edge(edge(truth, truth.size() - 1, 0, 0.01, 0.05, EdgeKind::kMatch, rng));
  const GraphSolveReport report = graph.optimise();
  ASSERT_TRUE(report.solved) << report.message;
  EXPECT_TRUE(report.outliers.empty());
  double closed_worst = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    closed_worst = std::max(closed_worst, error_m(graph.pose(i), truth[i]));
  }
  EXPECT_LT(closed_worst, chained_worst / 2);
  EXPECT_LT(error_m(graph.pose(truth.size() - 1), truth.back()), 0.05);
  EXPECT_LT(error_m(graph.pose(truth.size() - 1), truth.back()), drift / 3);
}

// Drifting odometry between consecutive scans and right matches between neighbours, plus one
// match 8 m and 20° wrong: the robust loss keeps the wrong edge from bending the map, and it is
// reported.
TEST(PoseGraph, OneWrongMatchDoesNotBendTheMap) {
  const std::vector<Pose> truth = square();
  std::mt19937_64 rng(3);
  PoseGraph graph;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    graph.add_node(i == 0
                       ? truth[0]
                       : compose(graph.pose(i - 1), relative_pose(truth[i - 1], truth[i]), 0, 0));
    if (i == 0) continue;
    graph.add_edge(edge(truth, i - 1, i, 0.2, 0.3, EdgeKind::kOdometry, rng));
    graph.add_edge(edge(truth, i - 1, i, 0.01, 0.05, EdgeKind::kMatch, rng));
  }
  graph.add_edge(edge(truth, truth.size() - 1, 0, 0.01, 0.05, EdgeKind::kMatch, rng));
  PoseGraph right = graph;
  ASSERT_TRUE(right.optimise().solved);

  GraphEdge wrong = edge(truth, 3, 9, 0.01, 0.05, EdgeKind::kMatch, rng);
  wrong.measured.x += 8;
  wrong.measured.yaw += deg2rad(20);
  graph.add_edge(wrong);
  const GraphSolveReport report = graph.optimise();
  ASSERT_TRUE(report.solved) << report.message;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT(error_m(graph.pose(i), right.pose(i)), 0.02) << "scan " << i;
    EXPECT_LT(error_m(graph.pose(i), truth[i]), 0.10) << "scan " << i;
  }
  ASSERT_EQ(report.outliers.size(), 1u);
  EXPECT_EQ(report.outliers[0], graph.edges().size() - 1);
}

TEST(PoseGraph, RefusesEdgesItCannotUse) {
  PoseGraph graph;
  graph.add_node(Pose{});
  graph.add_node(Pose{});
  EXPECT_THROW(graph.add_edge({0, 2, {}, Eigen::Matrix4d::Identity()}), std::invalid_argument);
  EXPECT_THROW(graph.add_edge({1, 1, {}, Eigen::Matrix4d::Identity()}), std::invalid_argument);
  Eigen::Matrix4d singular = Eigen::Matrix4d::Identity();
  singular(3, 3) = 0;
  EXPECT_THROW(graph.add_edge({0, 1, {}, singular}), std::invalid_argument);
  Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
  nan(0, 0) = std::nan("");
  EXPECT_THROW(graph.add_edge({0, 1, {}, nan}), std::invalid_argument);
  EXPECT_NO_THROW(graph.add_edge({0, 1, {}, Eigen::Matrix4d::Identity()}));
}

TEST(PoseGraph, TheFirstScanStaysWhereItIs) {
  PoseGraph graph;
  const Pose first = pose(5, 6, 7, 30);
  graph.add_node(first);
  graph.add_node(pose(0, 0, 0, 0));
  graph.add_edge({0, 1, {10, 0, 0, 0}, information(0.1, 1), EdgeKind::kOdometry});
  ASSERT_TRUE(graph.optimise().solved);
  EXPECT_EQ(graph.pose(0).x, first.x);
  EXPECT_EQ(graph.pose(0).yaw, first.yaw);
  EXPECT_NEAR(graph.pose(1).x, 5 + 10 * std::cos(deg2rad(30)), 1e-6);
  EXPECT_NEAR(graph.pose(1).y, 6 + 10 * std::sin(deg2rad(30)), 1e-6);
}

}  // namespace
}  // namespace scanplan
