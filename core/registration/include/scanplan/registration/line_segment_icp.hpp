#pragma once

#include <Eigen/Geometry>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

struct IcpConfig {
  int max_iterations = 60;
  // Outlier rejection: a correspondence farther than the current distance is dropped. The
  // distance starts wide, to reach from the initial guess, and shrinks by `shrink` whenever the
  // match has settled at it (a step under 10× the tolerances), down to its minimum, so that the
  // last iterations only listen to true neighbours.
  double max_correspondence_m = 2.0;
  double min_correspondence_m = 0.5;
  double shrink = 0.8;
  // Robust kernel (Geman-McClure) scale as a share of the current rejection distance (0: plain
  // least squares): at the 0.5 m floor, residuals beyond about 5 cm count less and less.
  double kernel_scale_per_distance = 0.1;
  // The source is thinned to one centroid per cube of this side before matching (0: as given);
  // the target keeps its resolution, since the segments are drawn between target points.
  double source_voxel_m = 0.0;
  // Converged once the distance is at its minimum and a step moves less than this and turns
  // less than this, or the mean squared error changes by less than this share.
  double translation_tolerance_m = 5e-4;
  double rotation_tolerance_rad = 5e-5;
  double relative_error_tolerance = 1e-4;
  // Fewer correspondences than this and the match is abandoned as having no overlap.
  int min_correspondences = 20;
  // OpenMP threads for the correspondence search (0: the OpenMP default). One by default: each
  // parallel pass is about a millisecond of work, and on a loaded machine the barrier at its end
  // costs more than that (2 threads measured 7x slower than 1 on the shared 2-core build machine).
  int num_threads = 1;
};

// Line-segment ICP (paper §4.1): each source point is matched not to its closest target point
// but to the segment joining its two closest target points, and the distance to that segment is
// minimised by Gauss-Newton over 4 or 6 DOF. (The paper measures from the reference point to a
// segment of the other scan; we query from the source side so that one k-d tree over the target
// serves every iteration.) Fills transform, iterations, converged and message.
RegistrationResult align_line_segment_icp(const PointCloud& target, const PointCloud& source,
                                          const Eigen::Isometry3d& initial, Dof dof,
                                          const IcpConfig& config);

}  // namespace scanplan
