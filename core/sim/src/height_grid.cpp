#include "scanplan/sim/height_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace scanplan {

HeightGrid::HeightGrid(const Eigen::Vector2d& origin, double cell_m, int cols, int rows,
                       std::vector<double> heights_m)
    : origin_(origin), cell_m_(cell_m), cols_(cols), rows_(rows), heights_m_(std::move(heights_m)) {
  if (!origin_.allFinite()) throw std::invalid_argument("height grid: origin must be finite");
  if (!(cell_m_ > 0) || !std::isfinite(cell_m_))
    throw std::invalid_argument("height grid: cell size must be a finite number above zero");
  if (cols_ < 2 || rows_ < 2)
    throw std::invalid_argument("height grid: needs at least 2 × 2 nodes to interpolate, got " +
                                std::to_string(cols_) + " × " + std::to_string(rows_));
  if (heights_m_.size() != static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_))
    throw std::invalid_argument("height grid: expected " + std::to_string(cols_ * rows_) +
                                " heights (cols × rows), got " + std::to_string(heights_m_.size()));
  for (const double h : heights_m_) {
    if (!std::isfinite(h)) throw std::invalid_argument("height grid: heights must be finite");
  }
  const auto [lo, hi] = std::minmax_element(heights_m_.begin(), heights_m_.end());
  min_height_ = *lo;
  max_height_ = *hi;
}

double HeightGrid::height(double x, double y) const {
  // Clamping the lattice coordinate (not the cell index) is what continues the edge outward.
  const double gx = std::clamp((x - origin_.x()) / cell_m_, 0.0, static_cast<double>(cols_ - 1));
  const double gy = std::clamp((y - origin_.y()) / cell_m_, 0.0, static_cast<double>(rows_ - 1));
  const int c0 = std::min(static_cast<int>(gx), cols_ - 2);
  const int r0 = std::min(static_cast<int>(gy), rows_ - 2);
  const double u = gx - c0, v = gy - r0;
  const double h00 = node(c0, r0), h10 = node(c0 + 1, r0);
  const double h01 = node(c0, r0 + 1), h11 = node(c0 + 1, r0 + 1);
  return h00 * (1 - u) * (1 - v) + h10 * u * (1 - v) + h01 * (1 - u) * v + h11 * u * v;
}

}  // namespace scanplan
