#include "scanplan/graph/pose_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace scanplan {
namespace {

void check_information(const GraphEdge& edge, const Eigen::Matrix4d& info) {
  if (!info.allFinite() || !info.isApprox(info.transpose(), 1e-9) ||
      Eigen::LLT<Eigen::Matrix4d>(info).info() != Eigen::Success) {
    throw std::invalid_argument("pose graph edge " + std::to_string(edge.from) + " → " +
                                std::to_string(edge.to) +
                                ": information matrix not symmetric positive definite");
  }
}

template <typename T>
T wrapped_angle(const T& a) {
  // atan2 of the angle's own sine and cosine: smooth for the automatic derivatives, unlike
  // remainder().
  using std::atan2, std::cos, std::sin;
  return atan2(sin(a), cos(a));
}

// r = L̃ · (relative(from, to) − measured), with L̃ᵀ L̃ = Ω, over blocks [x, y, z, yaw].
class EdgeCost {
 public:
  EdgeCost(const RelativePose& measured, const Eigen::Matrix4d& sqrt_information)
      : measured_(measured), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* from, const T* to, T* residual) const {
    using std::cos, std::sin;
    const T c = cos(from[3]), s = sin(from[3]);
    const T dx = to[0] - from[0], dy = to[1] - from[1];
    Eigen::Matrix<T, 4, 1> r;
    r[0] = c * dx + s * dy - T(measured_.x);
    r[1] = -s * dx + c * dy - T(measured_.y);
    r[2] = to[2] - from[2] - T(measured_.z);
    r[3] = wrapped_angle(to[3] - from[3] - T(measured_.yaw));
    Eigen::Map<Eigen::Matrix<T, 4, 1>> out(residual);
    out = sqrt_information_.cast<T>() * r;
    return true;
  }

 private:
  RelativePose measured_;
  Eigen::Matrix4d sqrt_information_;
};

// The upper factor U of Ω = Uᵀ U, so that |U r|² = rᵀ Ω r.
Eigen::Matrix4d sqrt_information(const Eigen::Matrix4d& information) {
  const Eigen::LLT<Eigen::Matrix4d> llt(information);
  return llt.matrixU();
}

}  // namespace

std::size_t PoseGraph::add_node(const Pose& estimate) {
  poses_.push_back(estimate);
  return poses_.size() - 1;
}

void PoseGraph::set_pose(std::size_t node, const Pose& estimate) {
  poses_.at(node) = estimate;
}

void PoseGraph::add_edge(const GraphEdge& edge) {
  if (edge.from >= poses_.size() || edge.to >= poses_.size()) {
    throw std::invalid_argument("pose graph edge " + std::to_string(edge.from) + " → " +
                                std::to_string(edge.to) + " names a scan not in the graph (" +
                                std::to_string(poses_.size()) + " scans)");
  }
  if (edge.from == edge.to) throw std::invalid_argument("pose graph edge from a scan to itself");
  check_information(edge, edge.information);
  edges_.push_back(edge);
}

void PoseGraph::set_measurement(std::size_t edge, const RelativePose& measured,
                                const Eigen::Matrix4d& information) {
  GraphEdge& e = edges_.at(edge);
  check_information(e, information);
  e.measured = measured;
  e.information = information;
}

double PoseGraph::whitened_error(std::size_t edge) const {
  const GraphEdge& e = edges_.at(edge);
  const RelativePose now = relative_pose(poses_[e.from], poses_[e.to]);
  Eigen::Vector4d r(now.x - e.measured.x, now.y - e.measured.y, now.z - e.measured.z,
                    std::remainder(now.yaw - e.measured.yaw, 2 * M_PI));
  return std::sqrt(std::max(0.0, r.dot(e.information * r)));
}

GraphSolveReport PoseGraph::optimise() {
  GraphSolveReport report;
  const auto t0 = std::chrono::steady_clock::now();
  if (poses_.size() < 2 || edges_.empty()) {
    report.solved = true;
    report.message = "nothing to optimise";
    return report;
  }
  std::vector<std::array<double, 4>> x(poses_.size());
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    x[i] = {poses_[i].x, poses_[i].y, poses_[i].z, poses_[i].yaw};
  }
  ceres::Problem problem;
  for (const GraphEdge& e : edges_) {
    auto* cost = new ceres::AutoDiffCostFunction<EdgeCost, 4, 4, 4>(
        new EdgeCost(e.measured, sqrt_information(e.information)));
    ceres::LossFunction* loss =
        e.kind == EdgeKind::kMatch ? new ceres::CauchyLoss(config_.robust_scale) : nullptr;
    problem.AddResidualBlock(cost, loss, x[e.from].data(), x[e.to].data());
  }
  // The first scan is the map frame; a node no edge reaches is not in the problem and stays.
  if (problem.HasParameterBlock(x[0].data())) problem.SetParameterBlockConstant(x[0].data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(options.sparse_linear_algebra_library_type))
    options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = config_.max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.solved = summary.termination_type == ceres::CONVERGENCE;
  report.message = summary.BriefReport();
  if (summary.IsSolutionUsable()) {
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      poses_[i].x = x[i][0];
      poses_[i].y = x[i][1];
      poses_[i].z = x[i][2];
      poses_[i].yaw = std::remainder(x[i][3], 2 * M_PI);
    }
  }
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    if (whitened_error(e) > config_.outlier_sigma) report.outliers.push_back(e);
  }
  report.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace scanplan
