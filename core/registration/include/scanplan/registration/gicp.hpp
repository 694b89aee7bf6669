#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/viewpoints.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

namespace detail {
class PointKdTree;
}

// One pass of GICP: both clouds thinned to `voxel_m`, correspondences up to
// `max_correspondence_m` apart.
struct GicpStage {
  double voxel_m;  // 0: the clouds as given
  double max_correspondence_m;
  double source_voxel_m = 0;  // the source thinned further (when larger than voxel_m)
};

// Generalized ICP (Segal et al. 2009, plane-to-plane), coarse to fine. Beyond the paper: its
// NDT → line-segment ICP needs the start within a few metres and reaches about a centimetre;
// scans the planner places 30–40 m apart share little and need both a wider reach and a finer
// end (issue 15). The coarse pass (1 m voxels, 5 m reach) pulls the source in from metres
// off; the fine pass (0.25 m, 1 m) reaches sub-centimetre accuracy. Lengths are for the
// campus and are scaled with the scene like every other length (RegistrationConfig).
struct GicpConfig {
  std::vector<GicpStage> stages{{1.0, 5.0}, {0.0, 1.0, 0.5}};
  // Each point's covariance is that of its 10 nearest neighbours in its own cloud (thinned to
  // the stage's voxels), flattened to a plane: eigenvalues (ε, 1, 1) along its eigenvectors, so
  // that two matched surfaces are pulled together across their normals and slide along them.
  double plane_epsilon = 1e-3;
  // Where the matcher knows where each cloud was seen from (MatchViews), a source point is not
  // paired with a target point whose surface faces another way: each normal turned toward the
  // scanner that saw it, their cosine at least this. 0 keeps every pair but the two faces of a
  // thin wall, a post or a trunk, which otherwise pull scans seen from opposite sides toward each
  // other by the thickness (on the campus's 10 cm fence: pairs 39 m apart 8–15 cm off from the
  // truth, 0.2–1.7 cm with the faces told apart).
  double min_normal_agreement = 0.0;
  int max_iterations_per_stage = 30;
  // A stage ends when a step moves less than this and turns less than this.
  double translation_tolerance_m = 1e-4;
  double rotation_tolerance_rad = 1e-5;
  // Fewer correspondences than this and the match is abandoned as having no overlap.
  int min_correspondences = 20;
};

// Clouds prepared once for GICP (thinned per stage, k-d trees, covariances as they are first
// needed), so that several starting points can be tried at the cost of the iterations only.
// align() fills the covariance cache: one thread at a time.
class GicpMatcher {
 public:
  // Without viewpoints (views unknown) every nearest pair within reach is used.
  GicpMatcher(const PointCloud& target, const PointCloud& source, const GicpConfig& config,
              const MatchViews& views = {});
  ~GicpMatcher();
  GicpMatcher(const GicpMatcher&) = delete;
  GicpMatcher& operator=(const GicpMatcher&) = delete;

  // Fills transform, iterations, converged and message.
  RegistrationResult align(const Eigen::Isometry3d& initial, Dof dof) const;

  // The k-d tree of a stage that takes the target as given (voxel_m 0: the fine stage by
  // default), over a copy of exactly its points in their order; null without such a stage.
  // Judging results against the same target can reuse it (AlignmentJudge).
  const detail::PointKdTree* unthinned_target_tree() const;

  struct Stage;  // one pass's clouds, covariances and k-d tree (gicp.cpp)

 private:
  GicpConfig config_;
  std::vector<std::unique_ptr<Stage>> stages_;
};

RegistrationResult align_gicp(const PointCloud& target, const PointCloud& source,
                              const Eigen::Isometry3d& initial, Dof dof, const GicpConfig& config,
                              const MatchViews& views = {});

}  // namespace scanplan
