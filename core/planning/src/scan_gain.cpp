#include "scanplan/planning/scan_gain.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "digest.hpp"

namespace scanplan {

ScanGainEvaluator::ScanGainEvaluator(const MlsMap& map, const RegionMap& regions, double alpha,
                                     const RegionConfig& region_config,
                                     const VisibilityConfig& visibility,
                                     const RegistrabilityField* registrability)
    : regions_(regions),
      registrability_(registrability),
      alpha_(alpha),
      completed_radius_cells2_(std::pow(region_config.completed_radius_m / map.cell_m(), 2)),
      predictor_(map, regions.cells, visibility) {
  if (!(alpha >= 0 && alpha <= 1)) {
    throw std::invalid_argument("alpha (paper Eq. 1 weight) must be in [0, 1], got " +
                                std::to_string(alpha));
  }
  if (!(region_config.completed_radius_m > 0)) {
    throw std::invalid_argument("completed_radius_m must be greater than zero");
  }
  if (regions.cells.cell_m != map.cell_m()) {
    throw std::invalid_argument("the region map and the MLS map must share one cell size");
  }
}

ScanGain ScanGainEvaluator::at(CellIndex b, double floor_z,
                               VisibilityPredictor::Workspace& ws) const {
  const auto& grid = regions_.cells;
  const std::int64_t bi = b.x - grid.origin.x, bj = b.y - grid.origin.y;
  std::size_t unscanned = 0, low_resolution = 0, unscanned_near = 0, mapped = 0;
  std::optional<RegistrabilityField::Forecast> forecast;
  if (registrability_) forecast.emplace(*registrability_);
  for (const std::uint32_t o : predictor_.visible_from(b, floor_z, ws)) {
    const Region r = grid.values[o];
    const auto di = static_cast<int>(static_cast<std::int64_t>(o % grid.cols) - bi);
    const auto dj = static_cast<int>(static_cast<std::int64_t>(o / grid.cols) - bj);
    if (forecast) forecast->add(o, di, dj);
    mapped += r == Region::kCompleted || r == Region::kLowResolution;
    if (r != Region::kUnscanned && r != Region::kLowResolution) continue;
    // C_B: within the completed radius of B, measured between cell centres as
    // segment_regions measures it.
    const bool near = di * di + dj * dj < completed_radius_cells2_;
    if (r == Region::kUnscanned) {
      ++unscanned;
      unscanned_near += near;
    } else if (near) {
      ++low_resolution;
    }
  }
  ScanGain g;
  g.unscanned_m2 = static_cast<double>(unscanned) * regions_.cell_area_m2();
  g.low_resolution_m2 = static_cast<double>(low_resolution) * regions_.cell_area_m2();
  g.completed_m2 = static_cast<double>(unscanned_near + low_resolution) * regions_.cell_area_m2();
  g.overlap_m2 = static_cast<double>(mapped) * regions_.cell_area_m2();
  g.f = alpha_ * g.unscanned_m2 + (1 - alpha_) * g.low_resolution_m2;
  if (forecast) g.registrability = forecast->result();
  return g;
}

std::uint64_t ScanGainEvaluator::digest() const {
  using digest::mix;
  std::uint64_t h = mix(mix(predictor_.digest(), alpha_), completed_radius_cells2_);
  return registrability_ ? mix(h, registrability_->digest()) : h;
}

std::uint64_t ScanGainEvaluator::cell_digest(std::size_t dense_offset) const {
  using digest::mix;
  const auto cols = static_cast<std::size_t>(predictor_.dense_cols());
  const CellIndex c{predictor_.dense_origin().x + static_cast<std::int32_t>(dense_offset % cols),
                    predictor_.dense_origin().y + static_cast<std::int32_t>(dense_offset / cols)};
  std::uint64_t h = predictor_.cell_digest(dense_offset);
  const auto o = regions_.cells.offset(c);
  if (!o) return mix(h, std::uint64_t{0xFF});  // outside the raster: never counted
  h = mix(h, static_cast<std::uint64_t>(regions_.cells.values[*o]));
  return registrability_ ? mix(h, registrability_->cell_digest(*o)) : h;
}

ScanGain ScanGainEvaluator::at(CellIndex b, double floor_z) const {
  auto ws = workspace();
  return at(b, floor_z, ws);
}

}  // namespace scanplan
