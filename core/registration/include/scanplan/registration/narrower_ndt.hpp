#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/ndt_grid.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

struct NdtConfig {
  // Paper §4.2 "Narrower NDT": the grid starts large for a global match and shrinks,
  // 20 m → 15 m → 10 m. RegistrationConfig scales these for short-range data.
  std::vector<double> cell_sizes_m{20.0, 15.0, 10.0};
  int max_iterations = 30;  // Newton steps per cell size
  // Yaw offsets (degrees) from which the first cell size is also started; the start ending at
  // the lowest NDT cost goes on to the finer cells. A reported yaw off by 15° or more puts
  // the far walls metres away, outside the basin of a local optimiser; a few turned starts at
  // the coarsest (cheapest) cell size widen it (campus benchmark, σ 10° yaw: 25 → 26 of 30
  // pairs; σ 20°: 18 → 25 of 30). {0}: the initial guess only.
  std::vector<double> yaw_hypotheses_deg{0.0, -12.0, 12.0, -24.0, 24.0};
  int hypothesis_iterations = 8;  // Newton steps each hypothesis gets before the best goes on
  // A translation search at the first cell size as well: shifts of −k..k steps of
  // cell × translation_search_step_per_cell in x and y, combined with every yaw offset, ranked
  // by the NDT cost of a sparse source (one point per cell × search_voxel_per_cell), the best
  // search_keep optimised. 0 steps: yaw offsets only, all of them optimised. (Campus
  // benchmark, 40 pairs at σ 4 m / 20°: 70% → 77.5% matched, +25 ms a match.)
  int translation_search_steps = 1;
  double translation_search_step_per_cell = 0.5;
  double search_voxel_per_cell = 0.4;
  int search_keep = 8;
  // Magnusson's p_o, the share of points the score treats as outliers (Magnusson 2009 eq. 6.7;
  // PCL's default too). It shapes the score: a larger value flattens it far from a Gaussian.
  double outlier_ratio = 0.55;
  // At each cell size the source is thinned to one point per cube of cell × this: a Gaussian
  // cannot use detail much finer than a fifth of its cell, and fewer points are faster.
  double source_voxel_per_cell = 0.2;
  NdtGridOptions grid;
  // A Newton step moves at most cell × this and turns at most max_step_rad: far from the
  // optimum the quadratic model overshoots, and the line search works from a bounded step.
  double max_step_per_cell = 0.25;
  double max_step_rad = 0.15;
  // Stop at a cell size when a step moves less than cell × this and turns less than this.
  double translation_tolerance_per_cell = 2e-4;
  double rotation_tolerance_rad = 2e-5;
  // Fewer source points than this near a Gaussian means the clouds do not overlap at that cell
  // size: the match is abandoned rather than reported on too little evidence.
  int min_matched_points = 20;
  // OpenMP threads for the score sums (0: the OpenMP default). One by default: each parallel
  // pass is about a millisecond of work, and on a loaded machine the barrier at its end costs
  // more than that (2 threads measured 7x slower than 1 on the shared 2-core build machine).
  int num_threads = 1;
};

// Narrower NDT (paper §4.2; NDT after Magnusson 2009 ch. 6): for each cell size in turn, the
// target's normal distributions and a Newton optimisation of the Gaussian score (Eq. 3) with its
// analytic gradient and Hessian, and a backtracking (Armijo) line search. The Hessian is made
// positive definite by taking the magnitude of its eigenvalues, so every step goes downhill.
// Beyond the paper: the first cell size starts from several hypotheses (yaw offsets and grid
// shifts, see NdtConfig), which widens the basin from a few metres to the reported-pose errors
// of the hard set. `target` and `source` are used as given (the caller downsamples). Fills
// transform, iterations, converged and message; the caller scores the result.
RegistrationResult align_narrower_ndt(const PointCloud& target, const PointCloud& source,
                                      const Eigen::Isometry3d& initial, Dof dof,
                                      const NdtConfig& config);

}  // namespace scanplan
