#include <gtest/gtest.h>

#include "mapping_test_support.hpp"
#include "scanplan/mapping/region_segmentation.hpp"

namespace scanplan {
namespace {

using test::slab;

TEST(RegionSegmentation, AreasMatchAHandCount) {
  MlsMap map;
  // Data on x 0..29, y 0..9 (300 cells); the target is x 0..39, y 0..9 (400 cells).
  map.insert(slab(0, 30, 0, 10, 0.0f));
  const auto target = TargetRegion::rectangle({0, 0}, {40, 10});
  // One scan point at (0.5, 0.5): cell centres (i + 0.5, j + 0.5) lie within 20 m when
  // i² + j² < 400, i.e. for j = 0..9: i ≤ 19, 19, 19, 19, 19, 19, 19, 18, 18, 17 → 196 cells.
  const RegionMap r = segment_regions(map, target, {{0.5, 0.5}});
  EXPECT_EQ(r.completed, 196u);
  EXPECT_EQ(r.low_resolution, 300u - 196u);
  EXPECT_EQ(r.unscanned, 100u);
  EXPECT_DOUBLE_EQ(r.detected_m2(), 300.0);
  EXPECT_EQ(r.at({19, 0}), Region::kCompleted);
  EXPECT_EQ(r.at({20, 0}), Region::kLowResolution);
  EXPECT_EQ(r.at({35, 5}), Region::kUnscanned);
  EXPECT_EQ(r.at({45, 5}), Region::kOutside);
}

TEST(RegionSegmentation, PolygonTargetCountsOnlyCellsWhoseCentreIsInside) {
  MlsMap map;
  map.insert(slab(0, 10, 0, 10, 0.0f));
  // A right triangle with legs of 10 m: cell (i, j) is in when its centre is, i + j + 1 ≤ 10
  // (centres on the hypotenuse count as inside) → 55 cells.
  const auto target = TargetRegion::polygon({{0, 0}, {10, 0}, {0, 10}});
  const RegionMap r = segment_regions(map, target, {{0, 0}});
  EXPECT_EQ(r.completed + r.low_resolution + r.unscanned, 55u);
}

}  // namespace
}  // namespace scanplan
