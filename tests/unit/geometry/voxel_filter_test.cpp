#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "scanplan/geometry/voxel_filter.hpp"

namespace scanplan {
namespace {

TEST(VoxelMap, ThinsEachScanAndKeepsColours) {
  PointCloud scan;
  scan.push_back({0.1f, 0.1f, 0.1f}, {255, 0, 0});
  scan.push_back({0.2f, 0.2f, 0.2f}, {0, 255, 0});  // nearest the voxel's centroid
  scan.push_back({0.3f, 0.3f, 0.3f}, {0, 0, 255});
  scan.push_back({1.5f, 0, 0}, {1, 2, 3});
  scan.push_back({std::nanf(""), 0, 0}, {9, 9, 9});
  VoxelMap map(1.0);
  map.add(scan);
  const PointCloud& out = map.cloud();
  ASSERT_EQ(out.size(), 2u);
  ASSERT_TRUE(out.has_colors());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out.points[i].x() < 1) {
      EXPECT_TRUE(out.points[i].isApprox(Eigen::Vector3f(0.2f, 0.2f, 0.2f)));
      EXPECT_EQ(out.colors[i], (Rgb{0, 255, 0})) << "the colour of the point that was kept";
    } else {
      EXPECT_EQ(out.colors[i], (Rgb{1, 2, 3}));
    }
  }
  // Same points as the plain voxel filter, which matching uses.
  EXPECT_EQ(voxel_downsample(scan, 1.0).points, out.points);
}

TEST(VoxelMap, KnownVoxelsKeepTheirFirstPointAndNewOnesAreMerged) {
  VoxelMap map(0.5);
  PointCloud first;
  first.push_back({0.1f, 0.1f, 0}, {10, 10, 10});
  first.push_back({5.1f, 0.1f, 0}, {20, 20, 20});
  map.add(first);
  PointCloud second;
  second.push_back({0.2f, 0.2f, 0}, {99, 99, 99});  // same voxel as the first point
  second.push_back({-3.1f, 0.1f, 0}, {30, 30, 30});
  second.push_back({2.6f, 0.1f, 0}, {40, 40, 40});
  map.add(second);
  const PointCloud& out = map.cloud();
  ASSERT_EQ(out.size(), 4u);
  int kept = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NE(out.colors[i], (Rgb{99, 99, 99})) << "a later scan does not move a settled voxel";
    kept += out.points[i].isApprox(Eigen::Vector3f(0.1f, 0.1f, 0)) ? 1 : 0;
  }
  EXPECT_EQ(kept, 1);
  // Replaying the same scans gives the same map, point for point: a restarted server rebuilds
  // and republishes what it had before.
  VoxelMap again(0.5);
  again.add(first);
  again.add(second);
  EXPECT_EQ(again.cloud().points, out.points);
}

TEST(VoxelMap, UncolouredScansAreGreyAndEmptyScansChangeNothing) {
  VoxelMap map(0.25);
  PointCloud plain;
  plain.points = {{1, 1, 1}, {2, 2, 2}};
  map.add(plain);
  ASSERT_EQ(map.cloud().size(), 2u);
  EXPECT_EQ(map.cloud().colors[0], VoxelMap::kUncolored);
  map.add(PointCloud{});
  EXPECT_EQ(map.cloud().size(), 2u);
}

TEST(VoxelMap, RefusesAVoxelSizeThatIsNotPositive) {
  EXPECT_THROW(VoxelMap(0), std::invalid_argument);
  EXPECT_THROW(VoxelMap(-1), std::invalid_argument);
  EXPECT_THROW(VoxelMap(std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace scanplan
