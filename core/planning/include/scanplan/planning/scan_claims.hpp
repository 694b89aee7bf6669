#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/planning/visibility.hpp"

namespace scanplan {

// Several robots on one map: what another robot's coming scan will cover, so that the next
// robot's plan counts only what is left (PlanInput::claimed).
//
// Marks in `regions` what scans from the `claims` (x, y, floor z) are predicted to see, as
// segment_regions would mark it after those scans: a seen U cell becomes C within the
// completed radius of the claim and M beyond it; a seen M cell within the radius becomes C.
// The counts follow. `predictor` must be built over `regions.cells`. A claim the predictor
// cannot stand a sensor at (off the map) sees nothing. Returns the number of cells changed.
std::size_t claim_predicted_scans(RegionMap& regions, const VisibilityPredictor& predictor,
                                  const std::vector<Eigen::Vector3d>& claims,
                                  const RegionConfig& config);

}  // namespace scanplan
