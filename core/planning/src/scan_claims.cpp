#include "scanplan/planning/scan_claims.hpp"

#include <cmath>
#include <stdexcept>

namespace scanplan {

std::size_t claim_predicted_scans(RegionMap& regions, const VisibilityPredictor& predictor,
                                  const std::vector<Eigen::Vector3d>& claims,
                                  const RegionConfig& config) {
  auto& grid = regions.cells;
  const double radius_cells2 = std::pow(config.completed_radius_m / grid.cell_m, 2);
  auto ws = predictor.workspace();
  std::size_t changed = 0;
  for (const Eigen::Vector3d& claim : claims) {
    const CellIndex b{static_cast<std::int32_t>(std::floor(claim.x() / grid.cell_m)),
                      static_cast<std::int32_t>(std::floor(claim.y() / grid.cell_m))};
    const std::vector<std::uint32_t>* seen = nullptr;
    try {
      seen = &predictor.visible_from(b, claim.z(), ws);
    } catch (const std::out_of_range&) {
      continue;  // off the mapped area: nothing known there to claim
    }
    const std::int64_t bi = b.x - grid.origin.x, bj = b.y - grid.origin.y;
    for (const std::uint32_t o : *seen) {
      Region& r = grid.values[o];
      if (r != Region::kUnscanned && r != Region::kLowResolution) continue;
      // Between cell centres, as ScanGainEvaluator measures C_B.
      const double di = static_cast<double>(static_cast<std::int64_t>(o % grid.cols) - bi);
      const double dj = static_cast<double>(static_cast<std::int64_t>(o / grid.cols) - bj);
      const bool near = di * di + dj * dj < radius_cells2;
      if (r == Region::kUnscanned) {
        --regions.unscanned;
        if (near) {
          r = Region::kCompleted;
          ++regions.completed;
        } else {
          r = Region::kLowResolution;
          ++regions.low_resolution;
        }
        ++changed;
      } else if (near) {
        r = Region::kCompleted;
        --regions.low_resolution;
        ++regions.completed;
        ++changed;
      }
    }
  }
  return changed;
}

}  // namespace scanplan
