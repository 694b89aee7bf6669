#pragma once

// Where a ray comes down onto the ground surface: a flat plane, or the bilinear height grid
// marched cell by cell. The ground is seen only from above: a ray counts where it crosses the
// surface going down, so a scanner never sees the underside of the terrain.

#include <Eigen/Core>
#include <optional>

#include "ray_primitives.hpp"
#include "scanplan/sim/height_grid.hpp"

namespace scanplan::detail {

class GroundCaster {
 public:
  GroundCaster(double flat_z, const std::optional<HeightGrid>& grid);

  // The first downward crossing in [t_min, t_max]; `normal` is the surface's upward normal.
  bool cast(const Ray& ray, double t_min, double t_max, double& t, Eigen::Vector3d& normal) const;

  // The same answer found by testing every cell of the (edge-extended) grid: the reference the
  // march is checked and benchmarked against.
  bool cast_every_cell(const Ray& ray, double t_min, double t_max, double& t,
                       Eigen::Vector3d& normal) const;

 private:
  // Cells are indexed −1 … n−1 per axis: −1 and n−1 are the unbounded strips beyond the
  // lattice, where the surface continues the edge nodes.
  bool cast_cell(const Ray& ray, int col, int row, double t_lo, double t_hi, double t_min,
                 double t_max, double& t, Eigen::Vector3d& normal) const;
  // The ray parameters at which it crosses the lines bounding column `col` (or row), ordered
  // along the ray; ±∞ for the open side of an edge strip or for a parallel ray.
  void axis_range(const Ray& ray, int axis, int index, double& t_lo, double& t_hi) const;
  int cell_index(int axis, double coord) const;
  double line(int axis, int index) const { return grid_->origin()[axis] + index * grid_->cell_m(); }
  int count(int axis) const { return axis == 0 ? grid_->cols() : grid_->rows(); }

  double flat_z_;
  std::optional<HeightGrid> grid_;
};

}  // namespace scanplan::detail
