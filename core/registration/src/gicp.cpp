#include "scanplan/registration/gicp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <memory>
#include <string>

#include "point_kdtree.hpp"
#include "pose_increment.hpp"
#include "scanplan/geometry/voxel_filter.hpp"

namespace scanplan {

using detail::Mat;
using detail::metres;
using detail::Vec;

namespace {

// Neighbours a point's covariance is taken over (Segal et al. and small_gicp use 10–20).
constexpr int kNeighbours = 10;

// A cloud with its k-d tree and each point's neighbourhood covariance, flattened to a plane
// (GicpConfig::plane_epsilon), and with viewpoints its surface normal turned toward the scanner
// that saw it. Both are computed when first asked for: at the planner's spacing most points of
// either scan never find a partner, and the neighbour search behind a covariance is the largest
// single cost of GICP.
class CovariedCloud {
 public:
  CovariedCloud(PointCloud cloud, Viewpoints views, float neighbour_radius, double epsilon)
      : cloud_(std::move(cloud)),
        views_(std::move(views)),
        tree_(cloud_.points),
        radius_sq_(neighbour_radius * neighbour_radius),
        epsilon_(epsilon),
        cov_(cloud_.size()),
        normal_(views_.known() ? cloud_.size() : 0, Eigen::Vector3d::Zero()),
        known_(cloud_.size(), 0) {}

  const detail::PointKdTree& tree() const { return tree_; }
  const PointCloud& cloud() const { return cloud_; }
  std::size_t size() const { return cloud_.size(); }

  // A point with too few neighbours for a plane gets an isotropic covariance: it still
  // attracts, but weakly in every direction.
  const Eigen::Matrix3d& covariance(std::uint32_t i) const {
    if (!known_[i]) {
      cov_[i] = plane_covariance(i);
      known_[i] = 1;
    }
    return cov_[i];
  }

  bool has_normals() const { return !normal_.empty(); }
  // Zero where the neighbourhood is too thin for a plane.
  const Eigen::Vector3d& normal(std::uint32_t i) const {
    covariance(i);
    return normal_[i];
  }

 private:
  Eigen::Matrix3d plane_covariance(std::uint32_t i) const {
    const Eigen::Vector3f& q = cloud_.points[i];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    if (!tree_.local_shape<kNeighbours>(q, radius_sq_, eig)) return Eigen::Matrix3d::Identity();
    if (has_normals()) {
      const Eigen::Vector3d n = eig.eigenvectors().col(0);
      normal_[i] = n.dot((views_.of(i) - q).cast<double>()) < 0 ? -n : n;
    }
    const Eigen::Vector3d values(epsilon_, 1.0, 1.0);
    return eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
  }

  PointCloud cloud_;
  Viewpoints views_;
  detail::PointKdTree tree_;  // over cloud_.points, which never move
  float radius_sq_;
  double epsilon_;
  mutable std::vector<Eigen::Matrix3d> cov_;
  mutable std::vector<Eigen::Vector3d> normal_;  // empty without viewpoints
  mutable std::vector<std::uint8_t> known_;
};

}  // namespace

struct GicpMatcher::Stage {
  Stage(const GicpStage& l, PointCloud target_points, Viewpoints target_views,
        PointCloud source_points, Viewpoints source_views, const GicpConfig& config)
      : lengths(l),
        // Neighbours farther than a correspondence may reach do not describe the surface there.
        target(std::move(target_points), std::move(target_views),
               static_cast<float>(l.max_correspondence_m), config.plane_epsilon),
        source(std::move(source_points), std::move(source_views),
               static_cast<float>(l.max_correspondence_m), config.plane_epsilon),
        min_normal_agreement(config.min_normal_agreement) {}
  GicpStage lengths;
  CovariedCloud target, source;
  double min_normal_agreement;
};

namespace {

template <int N>
struct Linearised {
  Mat<N> H = Mat<N>::Zero();
  Vec<N> g = Vec<N>::Zero();
  double error = 0;
  int matches = 0;
};

// The Mahalanobis residuals d = q − T·p under (C_q + R·C_p·Rᵀ)⁻¹, linearised at T for the left
// increment of pose_increment.hpp.
template <int N>
Linearised<N> linearise(const GicpMatcher::Stage& s, const Eigen::Isometry3d& T) {
  Linearised<N> out;
  const float max_sq =
      static_cast<float>(s.lengths.max_correspondence_m * s.lengths.max_correspondence_m);
  const Eigen::Matrix3d R = T.linear();
  const std::vector<Eigen::Vector3f>& source = s.source.cloud().points;
  for (std::uint32_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d p = T * source[i].cast<double>();
    std::uint32_t index[1];
    float sq[1];
    if (s.target.tree().nearest<1>(p.cast<float>(), max_sq, index, sq) == 0) continue;
    if (s.target.has_normals() && s.source.has_normals()) {
      // A point whose neighbourhood is too thin for a plane has no face to tell apart.
      const Eigen::Vector3d& nt = s.target.normal(index[0]);
      const Eigen::Vector3d& ns = s.source.normal(i);
      if (!nt.isZero() && !ns.isZero() && nt.dot(R * ns) < s.min_normal_agreement) continue;
    }
    const Eigen::Vector3d d = s.target.cloud().points[index[0]].cast<double>() - p;
    const Eigen::Matrix3d C =
        s.target.covariance(index[0]) + R * s.source.covariance(i) * R.transpose();
    const Eigen::Matrix3d W = C.inverse();
    // d(d)/dθ = −dp/dθ.
    const Eigen::Matrix<double, 3, N> J = -detail::point_jacobian<N>(p);
    const Eigen::Matrix<double, N, 3> JtW = J.transpose() * W;
    out.H.noalias() += JtW * J;
    out.g.noalias() += JtW * d;
    out.error += d.dot(W * d);
    ++out.matches;
  }
  return out;
}

}  // namespace

GicpMatcher::GicpMatcher(const PointCloud& target, const PointCloud& source,
                         const GicpConfig& config, const MatchViews& views)
    : config_(config) {
  // Viewpoints that do not describe these clouds are not used (nor are one cloud's alone).
  const bool viewed = views.target.fit(target.size()) && views.source.fit(source.size());
  // Each stage's clouds thinned as it asks, with the viewpoints of the points kept.
  const auto thinned = [&](const PointCloud& cloud, const Viewpoints& seen, double voxel_m) {
    if (!(voxel_m > 0)) return std::make_pair(cloud, viewed ? seen : Viewpoints{});
    std::vector<std::uint32_t> kept = voxel_kept(cloud, voxel_m);
    return std::make_pair(picked(cloud, kept), viewed ? seen.picked(kept) : Viewpoints{});
  };
  stages_.reserve(config.stages.size());
  for (const GicpStage& lengths : config.stages) {
    auto [t, t_views] = thinned(target, views.target, lengths.voxel_m);
    auto [s, s_views] =
        thinned(source, views.source, std::max(lengths.voxel_m, lengths.source_voxel_m));
    stages_.push_back(std::make_unique<Stage>(lengths, std::move(t), std::move(t_views),
                                              std::move(s), std::move(s_views), config));
  }
}

GicpMatcher::~GicpMatcher() = default;

const detail::PointKdTree* GicpMatcher::unthinned_target_tree() const {
  for (const auto& stage : stages_) {
    if (!(stage->lengths.voxel_m > 0)) return &stage->target.tree();
  }
  return nullptr;
}

RegistrationResult GicpMatcher::align(const Eigen::Isometry3d& initial, Dof dof) const {
  return detail::with_dof(dof, [&]<int N>() {
    RegistrationResult r;
    r.method = "gicp";
    r.transform = initial;
    if (stages_.empty()) {
      r.message = "no GICP stage configured";
      return r;
    }
    for (std::size_t k = 0; k < stages_.size(); ++k) {
      const Stage& s = *stages_[k];
      bool settled = false;
      for (int it = 0; it < config_.max_iterations_per_stage; ++it) {
        const Linearised<N> lin = linearise<N>(s, r.transform);
        ++r.iterations;
        if (lin.matches < config_.min_correspondences) {
          r.message = "only " + std::to_string(lin.matches) +
                      " source points have a target point within " +
                      metres(s.lengths.max_correspondence_m) +
                      ": the clouds do not overlap from this start";
          return r;
        }
        // A whisper of damping keeps a direction nothing constrains (open ground) from
        // producing an unbounded step.
        Mat<N> H = lin.H;
        H.diagonal().array() += 1e-6 * H.trace() / N;
        const Vec<N> delta = H.ldlt().solve(-lin.g);
        if (!delta.allFinite()) {
          r.message = "the GICP step is not finite";
          return r;
        }
        r.transform = detail::apply_increment<N>(r.transform, delta);
        const auto [moved, turned] = detail::step_size<N>(delta);
        if (moved < config_.translation_tolerance_m && turned < config_.rotation_tolerance_rad) {
          settled = true;
          break;
        }
      }
      // Only the last stage's ending says whether the match converged: a coarse stage that
      // runs out of iterations has still brought the source close enough for the next.
      if (k + 1 == stages_.size()) {
        r.converged = settled;
        r.ran_out = !settled;
        if (!settled) {
          r.message = "GICP did not settle within " +
                      std::to_string(config_.max_iterations_per_stage) + " iterations";
        }
      }
    }
    return r;
  });
}

RegistrationResult align_gicp(const PointCloud& target, const PointCloud& source,
                              const Eigen::Isometry3d& initial, Dof dof, const GicpConfig& config,
                              const MatchViews& views) {
  return GicpMatcher(target, source, config, views).align(initial, dof);
}

}  // namespace scanplan
