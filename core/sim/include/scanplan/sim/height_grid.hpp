#pragma once

#include <Eigen/Core>
#include <vector>

namespace scanplan {

// Ground heights on a regular x-y lattice of nodes (DESIGN.md "World file", ground "grid").
// Node (col, row) sits at origin + cell_m·(col, row). Between nodes the surface is bilinear;
// outside the lattice it continues the nearest edge, so a grid covering only a hillside leaves
// the rest of the site at the height of the grid's border.
class HeightGrid {
 public:
  // `heights_m` is row-major: heights_m[row * cols + col]. Throws std::invalid_argument for a
  // lattice that is not at least 2 × 2, a non-positive cell, a wrong count or non-finite values.
  HeightGrid(const Eigen::Vector2d& origin, double cell_m, int cols, int rows,
             std::vector<double> heights_m);

  double height(double x, double y) const;

  const Eigen::Vector2d& origin() const { return origin_; }
  double cell_m() const { return cell_m_; }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  double node(int col, int row) const {
    return heights_m_[static_cast<std::size_t>(row) * cols_ + col];
  }
  double min_height() const { return min_height_; }
  double max_height() const { return max_height_; }

 private:
  Eigen::Vector2d origin_;
  double cell_m_;
  int cols_, rows_;
  std::vector<double> heights_m_;
  double min_height_, max_height_;
};

}  // namespace scanplan
