#pragma once

// What 3DTK's slam6D does with its defaults (`bin/slam6D dir`), rebuilt for the tests, so that
// they can check how the `.reference` poses of the 3DTK sample scans were made: pairwise
// closest-point ICP of each scan against the one before (no metascan), every point of both
// scans (no reduction, no range limits), partners within 25 cm (`-d 25`, the data's unit being
// cm), each step the closed-form least-squares rigid motion of the pairs (Horn's quaternion
// method, `-a 1`; the SVD solution computed here is the same motion), at most 50 iterations
// (`-i 50`), started from the odometry moved by the previous scan's correction (slam6D's pose
// extrapolation, which for a pair means the relative odometry). Written from that description,
// independently of our matchers: it is the oracle their results are compared with, not a
// variant of them.

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cstddef>
#include <nanoflann.hpp>
#include <utility>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan::test_support {

// The target's points for nanoflann: a k-d tree of our own here, not the library's, so that the
// oracle shares no code with what it checks.
struct Slam6dCloudAdaptor {
  const std::vector<Eigen::Vector3f>* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

struct Slam6dIcpResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // source into target
  int iterations = 0;
  bool converged = false;  // stopped on a negligible step rather than on the iteration cap
};

inline Slam6dIcpResult slam6d_icp(const PointCloud& target, const PointCloud& source,
                                  const Eigen::Isometry3d& initial, int max_iterations,
                                  double max_distance_m = 0.25) {
  Slam6dIcpResult out;
  out.transform = initial;
  const Slam6dCloudAdaptor adaptor{&target.points};
  nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Slam6dCloudAdaptor>,
                                      Slam6dCloudAdaptor, 3, std::size_t>
      tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const float max_sq = static_cast<float>(max_distance_m * max_distance_m);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pairs;  // target point, moved source
  for (; out.iterations < max_iterations; ++out.iterations) {
    pairs.clear();
    Eigen::Vector3d mean_target = Eigen::Vector3d::Zero(), mean_source = Eigen::Vector3d::Zero();
    for (const auto& p : source.points) {
      const Eigen::Vector3d d = out.transform * p.cast<double>();
      const Eigen::Vector3f q = d.cast<float>();
      std::size_t index = 0;
      float sq = 0;
      if (tree.knnSearch(q.data(), 1, &index, &sq) != 1 || sq > max_sq) continue;
      const Eigen::Vector3d m = target.points[index].cast<double>();
      pairs.emplace_back(m, d);
      mean_target += m;
      mean_source += d;
    }
    if (pairs.size() < 3) return out;
    mean_target /= static_cast<double>(pairs.size());
    mean_source /= static_cast<double>(pairs.size());
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    for (const auto& [m, d] : pairs) H += (d - mean_source) * (m - mean_target).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d V = svd.matrixV();
    if ((V * svd.matrixU().transpose()).determinant() < 0) V.col(2) *= -1;  // a reflection
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = V * svd.matrixU().transpose();
    step.translation() = mean_target - step.linear() * mean_source;
    out.transform = step * out.transform;
    if (step.translation().norm() < 1e-6 && Eigen::AngleAxisd(step.linear()).angle() < 1e-7) {
      ++out.iterations;
      out.converged = true;
      return out;
    }
  }
  return out;
}

}  // namespace scanplan::test_support
