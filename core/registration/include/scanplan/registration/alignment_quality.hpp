#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <optional>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

// How well a source cloud sits on a target cloud under a transform, judged the same way for
// every matching method so that their results compare.
struct AlignmentQuality {
  // Paper Eq. 2: Σ_j ‖m_i − (R·d_j + t)‖² over source points d_j with m_i the closest target
  // point, each term truncated at score_max_distance² (see evaluate_alignment).
  double score = 0;
  double rmse = 0;          // over inliers only
  double inlier_ratio = 0;  // inliers / points
  std::size_t inliers = 0;  // source points with a target point within inlier_distance
  std::size_t points = 0;   // source points scored
  // How firmly the inliers pin the pose down in its weakest direction: the smallest eigenvalue
  // of the point-to-plane information matrix Σ a·aᵀ / inliers, a = [n; (p×n)/L] over the
  // parameters of `dof` (n the target's surface normal at the match, L the RMS radius of the
  // inliers, so rotation and translation weigh alike). Roughly the share of inliers that
  // constrain that direction: near 0 in a corridor (nothing stops sliding along it) or on open
  // ground, a few per cent and more where walls face several ways.
  double weakest_constraint = 0;
  // What the same inliers say of the pose's uncertainty, for the pose graph: Σ a·aᵀ / inliers
  // with a = [n; ((p − o) × n)_z], o the source's origin in the target frame, over x, y, z
  // (metres) and the yaw about o (radians). Divided by the variance of one point-to-plane
  // distance it is the information of the 4 parameters, as if the whole match weighed as
  // much as one point on every surface it touches: points on the same wall are not independent
  // measurements, and counting each would make every match look millimetre-sure. Zero unless
  // with_constraint.
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  // The median distance of the inliers from the target's surface along its normal (those where
  // the target forms a surface): how far apart the two scans' surfaces are, which the range
  // noise and the alignment make, without the sampling's spacing. Zero unless with_constraint.
  double median_plane_distance_m = 0;
  // The same over the inliers on walls (the target's normal within 45° of level) alone, and how
  // many there are: on open ground a horizontal error hides under the floor's distance of zero.
  double median_wall_distance_m = 0;
  std::size_t wall_inliers = 0;
};

namespace detail {
class PointKdTree;
}

// evaluate_alignment with the target's k-d tree built once, for judging several results
// against the same target (search-gicp's hypotheses). Keeps a reference to `target`, and to
// `tree` when given: one already built over exactly target's points, in their order (GICP's
// over the unthinned target, GicpMatcher::unthinned_target_tree), which must outlive the judge.
class AlignmentJudge {
 public:
  explicit AlignmentJudge(const PointCloud& target, const detail::PointKdTree* tree = nullptr);
  ~AlignmentJudge();
  AlignmentJudge(const AlignmentJudge&) = delete;
  AlignmentJudge& operator=(const AlignmentJudge&) = delete;

  AlignmentQuality evaluate(const PointCloud& source, const Eigen::Isometry3d& source_to_target,
                            Dof dof, double score_max_distance_m, double inlier_distance_m,
                            bool with_constraint = true) const;

  // The shape of the target's surface near q, from its up to 8 nearest points within radius_m
  // (nothing with fewer than 5): the spreads (eigenvalues of their scatter, ascending) and the
  // direction of the least, the surface's normal where they make a plane.
  struct LocalShape {
    Eigen::Vector3d spread;
    Eigen::Vector3d normal;
  };
  std::optional<LocalShape> local_shape(const Eigen::Vector3f& q, double radius_m) const;

  const PointCloud& target() const { return target_; }

 private:
  const PointCloud& target_;
  std::unique_ptr<detail::PointKdTree> own_tree_;
  const detail::PointKdTree* tree_;
};

// Scores `source` moved by `source_to_target` against `target`. The paper does not say how
// Eq. 2 treats points seen by one scan only; without a cut they dominate the sum and the score
// says more about the overlap than about the match, so each term is min(d², score_max²).
// `weakest_constraint` needs a surface normal per inlier, which costs as much as the rest: it is
// left at 0 unless `with_constraint`.
AlignmentQuality evaluate_alignment(const PointCloud& target, const PointCloud& source,
                                    const Eigen::Isometry3d& source_to_target, Dof dof,
                                    double score_max_distance_m, double inlier_distance_m,
                                    bool with_constraint = true);

}  // namespace scanplan
