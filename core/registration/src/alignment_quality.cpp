#include "scanplan/registration/alignment_quality.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "point_kdtree.hpp"

namespace scanplan {
namespace {

constexpr int kNormalNeighbours = 8;

// The target surface's unit normal near q from its nearest points, or nothing where they do not
// form a surface (too few, or spread along a line rather than a plane).
bool surface_normal(const detail::PointKdTree& tree, const Eigen::Vector3f& q, float max_sq,
                    Eigen::Vector3d& normal) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  if (!tree.local_shape<kNormalNeighbours>(q, max_sq, eig)) return false;
  // A plane has one small and two large eigenvalues; a line (a pole, an edge) has two small.
  if (eig.eigenvalues()[1] <= 0 || eig.eigenvalues()[0] > 0.1 * eig.eigenvalues()[1]) return false;
  normal = eig.eigenvectors().col(0);
  return true;
}

double median_of(std::vector<double>& v) {
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

}  // namespace

AlignmentJudge::AlignmentJudge(const PointCloud& target, const detail::PointKdTree* tree)
    : target_(target),
      own_tree_(tree ? nullptr : std::make_unique<detail::PointKdTree>(target.points)),
      tree_(tree ? tree : own_tree_.get()) {}

AlignmentJudge::~AlignmentJudge() = default;

AlignmentQuality evaluate_alignment(const PointCloud& target, const PointCloud& source,
                                    const Eigen::Isometry3d& source_to_target, Dof dof,
                                    double score_max_distance_m, double inlier_distance_m,
                                    bool with_constraint) {
  return AlignmentJudge(target).evaluate(source, source_to_target, dof, score_max_distance_m,
                                         inlier_distance_m, with_constraint);
}

std::optional<AlignmentJudge::LocalShape> AlignmentJudge::local_shape(const Eigen::Vector3f& q,
                                                                      double radius_m) const {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  const auto max_sq = static_cast<float>(radius_m * radius_m);
  if (!tree_->local_shape<kNormalNeighbours>(q, max_sq, eig)) return std::nullopt;
  return LocalShape{eig.eigenvalues(), eig.eigenvectors().col(0)};
}

AlignmentQuality AlignmentJudge::evaluate(const PointCloud& source,
                                          const Eigen::Isometry3d& source_to_target, Dof dof,
                                          double score_max_distance_m, double inlier_distance_m,
                                          bool with_constraint) const {
  AlignmentQuality q;
  q.points = source.size();
  if (target_.empty() || source.empty()) return q;
  const detail::PointKdTree& tree = *tree_;
  const Eigen::Isometry3f T = source_to_target.cast<float>();
  const double cut_sq = score_max_distance_m * score_max_distance_m;
  const double inlier_sq = inlier_distance_m * inlier_distance_m;
  const float search_sq = static_cast<float>(std::max(cut_sq, inlier_sq));
  const float normal_sq = static_cast<float>(16 * inlier_sq);
  double inlier_sum = 0;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> planar;  // point, normal
  std::vector<double> plane_distance, wall_distance;
  for (const auto& p : source.points) {
    const Eigen::Vector3f moved = T * p;
    std::uint32_t index[1];
    float sq[1];
    const int found = tree.nearest<1>(moved, search_sq, index, sq);
    const double d2 = found ? static_cast<double>(sq[0]) : cut_sq;
    q.score += std::min(d2, cut_sq);
    if (found && d2 <= inlier_sq) {
      ++q.inliers;
      inlier_sum += d2;
      Eigen::Vector3d n;
      if (with_constraint && surface_normal(tree, moved, normal_sq, n)) {
        planar.emplace_back(moved.cast<double>(), n);
        const Eigen::Vector3d m = target_.points[index[0]].cast<double>();
        plane_distance.push_back(std::abs(n.dot(moved.cast<double>() - m)));
        if (std::abs(n.z()) < std::sqrt(0.5)) wall_distance.push_back(plane_distance.back());
      }
    }
  }
  q.inlier_ratio = static_cast<double>(q.inliers) / static_cast<double>(q.points);
  q.rmse = q.inliers ? std::sqrt(inlier_sum / static_cast<double>(q.inliers)) : 0.0;
  if (planar.empty()) return q;
  q.median_plane_distance_m = median_of(plane_distance);
  q.wall_inliers = wall_distance.size();
  if (!wall_distance.empty()) q.median_wall_distance_m = median_of(wall_distance);

  double radius_sq = 0;
  for (const auto& [p, n] : planar) radius_sq += p.squaredNorm();
  const double L = std::max(std::sqrt(radius_sq / static_cast<double>(planar.size())), 1e-6);
  const int dims = dof == Dof::k4 ? 4 : 6;
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(dims, dims);
  Eigen::VectorXd a(dims);
  for (const auto& [p, n] : planar) {
    const Eigen::Vector3d moment = p.cross(n) / L;
    a.head<3>() = n;
    if (dof == Dof::k4) {
      a[3] = moment.z();
    } else {
      a.tail<3>() = moment;
    }
    info += a * a.transpose();
  }
  info /= static_cast<double>(q.inliers);
  const Eigen::Vector3d origin = source_to_target.translation();
  Eigen::Vector4d b;
  for (const auto& [p, n] : planar) {
    b.head<3>() = n;
    b[3] = (p - origin).cross(n).z();
    q.information += b * b.transpose();
  }
  q.information /= static_cast<double>(q.inliers);
  q.weakest_constraint = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(info).eigenvalues()[0];
  return q;
}

}  // namespace scanplan
