#include "scanplan/mapping/region_segmentation.hpp"

#include <cmath>

namespace scanplan {

RegionMap segment_regions(const MlsMap& map, const TargetRegion& target,
                          const std::vector<Eigen::Vector2d>& scan_points,
                          const RegionConfig& config) {
  const CellIndex lo = map.index_of(target.min().x(), target.min().y());
  const CellIndex hi = map.index_of(target.max().x(), target.max().y());
  RegionMap out;
  out.cells =
      CellGrid<Region>(lo, hi.x - lo.x + 1, hi.y - lo.y + 1, map.cell_m(), Region::kOutside);
  const double r2 = config.completed_radius_m * config.completed_radius_m;
  for (int j = 0; j < out.cells.rows; ++j) {
    for (int i = 0; i < out.cells.cols; ++i) {
      const CellIndex c{lo.x + i, lo.y + j};
      const Eigen::Vector2d center = map.center_of(c);
      if (!target.contains(center.x(), center.y())) continue;
      Region& r = out.cells.values[static_cast<std::size_t>(j) * out.cells.cols + i];
      if (!map.cell(c)) {
        r = Region::kUnscanned;
        ++out.unscanned;
        continue;
      }
      bool near = false;
      for (const auto& s : scan_points) {
        if ((s - center).squaredNorm() < r2) {
          near = true;
          break;
        }
      }
      r = near ? Region::kCompleted : Region::kLowResolution;
      ++(near ? out.completed : out.low_resolution);
    }
  }
  return out;
}

}  // namespace scanplan
