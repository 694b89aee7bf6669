#include "scanplan/registration/ground_level.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace scanplan {
namespace {

// The lowest z of the points in each cell of a square of cells centred on `centre`.
class LowestGrid {
 public:
  LowestGrid(const Eigen::Vector2d& centre, const GroundLevelConfig& config)
      : centre_(centre),
        cell_m_(config.cell_m),
        half_(static_cast<int>(std::ceil(config.radius_m / config.cell_m))),
        side_(2 * half_ + 1),
        radius2_(config.radius_m * config.radius_m),
        lowest_(static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_),
                std::numeric_limits<float>::infinity()) {}

  void add(const Eigen::Vector3d& p) {
    const Eigen::Vector2d d = p.head<2>() - centre_;
    if (!p.allFinite() || d.squaredNorm() > radius2_) return;
    const int i = static_cast<int>(std::floor(d.x() / cell_m_)) + half_;
    const int j = static_cast<int>(std::floor(d.y() / cell_m_)) + half_;
    if (i < 0 || j < 0 || i >= side_ || j >= side_) return;
    float& z = lowest_[static_cast<std::size_t>(j) * static_cast<std::size_t>(side_) +
                       static_cast<std::size_t>(i)];
    z = std::min(z, static_cast<float>(p.z()));
  }
  const std::vector<float>& lowest() const { return lowest_; }

 private:
  Eigen::Vector2d centre_;
  double cell_m_;
  int half_, side_;
  double radius2_;
  std::vector<float> lowest_;
};

}  // namespace

std::optional<double> ground_offset(const PointCloud& target, const PointCloud& scan,
                                    const Eigen::Isometry3d& scan_to_target,
                                    const GroundLevelConfig& config) {
  if (!(config.radius_m > 0 && config.cell_m > 0)) return std::nullopt;
  const Eigen::Vector2d centre = scan_to_target.translation().head<2>();
  LowestGrid in_map(centre, config), in_scan(centre, config);
  for (const auto& p : target.points) in_map.add(p.cast<double>());
  for (const auto& p : scan.points) in_scan.add(scan_to_target * p.cast<double>());
  std::vector<float> diffs;
  for (std::size_t k = 0; k < in_map.lowest().size(); ++k) {
    const float a = in_map.lowest()[k], b = in_scan.lowest()[k];
    if (std::isfinite(a) && std::isfinite(b)) diffs.push_back(a - b);
  }
  if (static_cast<int>(diffs.size()) < std::max(1, config.min_cells)) return std::nullopt;
  const auto mid = diffs.begin() + static_cast<std::ptrdiff_t>(diffs.size() / 2);
  std::nth_element(diffs.begin(), mid, diffs.end());
  return static_cast<double>(*mid);
}

}  // namespace scanplan
