#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "scanplan/geometry/viewpoints.hpp"
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

namespace scanplan {
namespace {

// What voxel_downsample promises, computed the slow way: per voxel (z, then y, then x ascending)
// the point nearest its points' centroid, the first of equals.
std::vector<Eigen::Vector3f> thinned_by_definition(const PointCloud& cloud, double voxel_m) {
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, std::vector<std::size_t>> voxels;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite()) continue;
    const auto cell = [&](int a) { return static_cast<std::int64_t>(std::floor(p[a] / voxel_m)); };
    voxels[{cell(2), cell(1), cell(0)}].push_back(i);
  }
  std::vector<Eigen::Vector3f> out;
  for (const auto& [key, members] : voxels) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::size_t i : members) sum += cloud.points[i].cast<double>();
    const Eigen::Vector3d centroid = sum / static_cast<double>(members.size());
    std::size_t best = members.front();
    double best_sq = std::numeric_limits<double>::max();
    for (const std::size_t i : members) {
      const double d = (cloud.points[i].cast<double>() - centroid).squaredNorm();
      if (d < best_sq) best_sq = d, best = i;
    }
    out.push_back(cloud.points[best]);
  }
  return out;
}

TEST(VoxelDownsample, KeepsThePointNearestEachVoxelsCentroidInVoxelOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-60.0f, 60.0f);
  PointCloud cloud;
  for (int i = 0; i < 50000; ++i) {
    const Eigen::Vector3f p(coordinate(rng), coordinate(rng), 0.05f * coordinate(rng));
    cloud.push_back(p, {});
    if (i % 7 == 0) cloud.push_back(p, {});  // equal points: the first is kept
  }
  cloud.push_back(Eigen::Vector3f(std::nanf(""), 0, 0), {});
  for (const double voxel : {0.25, 1.0, 3.0}) {
    const std::vector<Eigen::Vector3f> expected = thinned_by_definition(cloud, voxel);
    EXPECT_EQ(voxel_downsample(cloud, voxel).points, expected) << voxel << " m voxels";
    EXPECT_EQ(picked(cloud, voxel_kept(cloud, voxel)).points, expected) << voxel << " m voxels";
  }
}

TEST(Viewpoints, FollowTheirPointsThroughThinningAndMoves) {
  PointCloud cloud;  // two scans' points merged: the first seen from a, the second from b
  cloud.push_back({0.1f, 0.1f, 0.1f}, {1, 1, 1});
  cloud.push_back({5.1f, 0.1f, 0.1f}, {2, 2, 2});
  cloud.push_back({0.2f, 0.2f, 0.2f}, {3, 3, 3});
  cloud.push_back({std::nanf(""), 0, 0}, {4, 4, 4});
  const Eigen::Vector3f a(-10, 0, 1), b(10, 0, 1);
  const Viewpoints views{{a, b}, {0, 1, 1, 0}};
  ASSERT_TRUE(views.fit(cloud.size()));
  EXPECT_FALSE(views.fit(3)) << "one index a point";
  EXPECT_FALSE((Viewpoints{{a}, {0, 1, 0, 0}}).fit(4)) << "an index past the origins";
  EXPECT_FALSE(Viewpoints{}.fit(4)) << "unknown";
  EXPECT_TRUE(Viewpoints::single(a).fit(1000));

  const std::vector<std::uint32_t> kept = voxel_kept(cloud, 1.0);
  ASSERT_EQ(kept.size(), 2u) << "the NaN dropped, the two near the origin one voxel";
  const PointCloud thin = picked(cloud, kept);
  const Viewpoints thin_views = views.picked(kept);
  ASSERT_TRUE(thin_views.fit(thin.size()));
  for (std::size_t i = 0; i < thin.size(); ++i) {
    EXPECT_EQ(thin.points[i], cloud.points[kept[i]]);
    EXPECT_EQ(thin.colors[i], cloud.colors[kept[i]]) << "colours kept";
    EXPECT_EQ(thin_views.of(i), thin.points[i].x() > 1 ? b : a) << "point " << i;
  }
  const Eigen::Isometry3f move(Eigen::Translation3f(1, 2, 3));
  EXPECT_EQ(views.transformed(move).of(1), Eigen::Vector3f(11, 2, 4));
  EXPECT_EQ(Viewpoints::single(a).picked(kept).of(1), a) << "one origin stays one origin";
}

}  // namespace
}  // namespace scanplan
