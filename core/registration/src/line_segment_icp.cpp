#include "scanplan/registration/line_segment_icp.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "point_kdtree.hpp"
#include "pose_increment.hpp"
#include "scanplan/geometry/voxel_filter.hpp"

namespace scanplan {
namespace {

using detail::Mat;
using detail::metres;
using detail::Vec;

template <int N>
struct NormalEquations {
  Mat<N> H = Mat<N>::Zero();
  Vec<N> g = Vec<N>::Zero();
  double squared_error = 0;
  int matches = 0;

  void add(const NormalEquations& o) {
    H += o.H;
    g += o.g;
    squared_error += o.squared_error;
    matches += o.matches;
  }
};

// The point of segment [a, b] closest to p, and whether it lies strictly inside the segment
// (then the residual is perpendicular to the segment and only that component may be used).
struct SegmentFoot {
  Eigen::Vector3d point;
  Eigen::Vector3d direction;  // unit, valid when inside
  bool inside = false;
};

SegmentFoot closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_sq = ab.squaredNorm();
  if (length_sq < 1e-12) return {a, Eigen::Vector3d::Zero(), false};
  const double t = (p - a).dot(ab) / length_sq;
  if (t <= 0) return {a, Eigen::Vector3d::Zero(), false};
  if (t >= 1) return {b, Eigen::Vector3d::Zero(), false};
  return {a + t * ab, ab / std::sqrt(length_sq), true};
}

template <int N>
NormalEquations<N> linearise(const detail::PointKdTree& tree,
                             const std::vector<Eigen::Vector3f>& source, const Eigen::Isometry3d& T,
                             double max_distance, double kernel, int threads) {
  const double kernel_sq = kernel * kernel;
  NormalEquations<N> total;
  const float max_sq = static_cast<float>(max_distance * max_distance);
  const int n = static_cast<int>(source.size());
#pragma omp parallel num_threads(threads)
  {
    NormalEquations<N> local;
#pragma omp for schedule(static) nowait
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = T * source[i].cast<double>();
      std::uint32_t index[2];
      float sq[2];
      const int found = tree.nearest<2>(p.cast<float>(), max_sq, index, sq);
      if (found == 0) continue;
      const Eigen::Vector3d a = tree.point(index[0]).cast<double>();
      const SegmentFoot foot = found == 2
                                   ? closest_on_segment(p, a, tree.point(index[1]).cast<double>())
                                   : SegmentFoot{a, Eigen::Vector3d::Zero(), false};
      const Eigen::Vector3d r = p - foot.point;
      const Eigen::Matrix<double, 3, N> J = detail::point_jacobian<N>(p);
      // Geman-McClure: near-zero weight for residuals well beyond the kernel scale. Parts seen
      // by one scan only still find a "closest" segment within the rejection distance, and
      // their pull, summed over an occlusion border, biases a plain least-squares fit by cm.
      const double s2 = r.squaredNorm() / kernel_sq;
      const double wgt = kernel_sq > 0 ? 1.0 / ((1.0 + s2) * (1.0 + s2)) : 1.0;
      // Inside the segment the distance is to its line: moving along the line changes nothing,
      // so the projector P = I − uuᵀ removes that direction (JᵀPJ). At an end it is to a point.
      if (foot.inside) {
        const Eigen::Matrix<double, 1, N> uJ = foot.direction.transpose() * J;
        local.H += wgt * (J.transpose() * J - uJ.transpose() * uJ);
      } else {
        local.H += wgt * J.transpose() * J;
      }
      local.g += wgt * J.transpose() * r;  // P·r = r: r is already perpendicular inside the segment
      local.squared_error += r.squaredNorm();
      ++local.matches;
    }
#pragma omp critical
    total.add(local);
  }
  return total;
}

template <int N>
RegistrationResult align(const PointCloud& target, const PointCloud& source,
                         const Eigen::Isometry3d& initial, const IcpConfig& config) {
  RegistrationResult result;
  result.method = "icp";
  result.transform = initial;
  const PointCloud thinned =
      config.source_voxel_m > 0 ? voxel_downsample(source, config.source_voxel_m) : PointCloud{};
  const std::vector<Eigen::Vector3f>& points =
      config.source_voxel_m > 0 ? thinned.points : source.points;
  if (target.size() < 2 || points.empty()) {
    result.message = "ICP needs at least two target points and one source point";
    return result;
  }
  const detail::PointKdTree tree(target.points);
#ifdef _OPENMP
  const int threads = config.num_threads > 0 ? config.num_threads : omp_get_max_threads();
#else
  const int threads = config.num_threads > 0 ? config.num_threads : 1;
#endif
  const double floor_distance = std::min(config.min_correspondence_m, config.max_correspondence_m);
  double distance = config.max_correspondence_m;
  double previous_error = -1;  // at the same rejection distance, else -1
  for (; result.iterations < config.max_iterations; ++result.iterations) {
    const NormalEquations<N> eq =
        linearise<N>(tree, points, result.transform, distance,
                     config.kernel_scale_per_distance * distance, threads);
    if (eq.matches < std::max(config.min_correspondences, N)) {
      result.message = "only " + std::to_string(eq.matches) + " of " +
                       std::to_string(points.size()) +
                       " source points have a target point within " + metres(distance) +
                       ": the clouds do not overlap from this start";
      return result;
    }
    // A whisper of damping keeps the solve defined when the scene leaves a direction
    // unconstrained (a long corridor); it does not bias well-posed problems measurably.
    const Mat<N> damped = eq.H + 1e-9 * eq.H.trace() * Mat<N>::Identity();
    const Vec<N> step = damped.ldlt().solve(-eq.g);
    if (!step.allFinite()) {
      result.message = "ICP normal equations are singular";
      return result;
    }
    result.transform = detail::apply_increment<N>(result.transform, step);
    const double error = eq.squared_error / eq.matches;
    const auto [moved, turned] = detail::step_size<N>(step);
    const bool at_floor = distance <= floor_distance;
    const bool small_step =
        moved < config.translation_tolerance_m && turned < config.rotation_tolerance_rad;
    const bool flat_error = previous_error >= 0 && std::abs(previous_error - error) <=
                                                       config.relative_error_tolerance * error;
    if (at_floor && (small_step || flat_error)) {
      ++result.iterations;
      result.converged = true;
      return result;
    }
    // The rejection distance (and with it the kernel) narrows only once the match has settled
    // at the current one: narrowed early, it would cut off the very partners that still have
    // to pull the scan in from an initial error of tens of centimetres.
    const bool settled =
        moved < 10 * config.translation_tolerance_m && turned < 10 * config.rotation_tolerance_rad;
    const double next_distance =
        settled || flat_error ? std::max(floor_distance, distance * config.shrink) : distance;
    previous_error = next_distance == distance ? error : -1;
    distance = next_distance;
  }
  result.message =
      "ICP did not converge within " + std::to_string(config.max_iterations) + " iterations";
  return result;
}

}  // namespace

RegistrationResult align_line_segment_icp(const PointCloud& target, const PointCloud& source,
                                          const Eigen::Isometry3d& initial, Dof dof,
                                          const IcpConfig& config) {
  return detail::with_dof(dof, [&]<int N>() { return align<N>(target, source, initial, config); });
}

}  // namespace scanplan
