// The map exports' edge cases (the formats themselves are read back by an independent reader in
// tests/integration/exports.test.mjs).
#include <gtest/gtest.h>

#include <cstring>

#include "scanplan/io/map_export.hpp"
#include "scanplan/io/ply_io.hpp"

namespace scanplan {
namespace {

std::shared_ptr<const PointCloud> cloud(std::vector<Eigen::Vector3f> points, bool colours) {
  auto c = std::make_shared<PointCloud>();
  for (const auto& p : points) {
    c->points.push_back(p);
    if (colours) c->colors.push_back({10, 20, 30});
  }
  return c;
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

TEST(MapExport, PlyKeepsEveryScansPointsWithGreyWhereThereIsNoColour) {
  const std::vector<MapPart> parts = {
      {3, cloud({{1, 2, 3}, {4, 5, 6}}, true)}, {7, cloud({{-1, -2, -3}}, false)}, {8, nullptr}};
  const std::string bytes = map_ply_bytes(parts, {"map frame"});
  const PointCloud back = read_ply_bytes(bytes, "map.ply");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back.points[2], Eigen::Vector3f(-1, -2, -3));
  EXPECT_EQ(back.colors[0], (Rgb{10, 20, 30}));
  EXPECT_EQ(back.colors[2], (Rgb{128, 128, 128}));
  // The scan id closes each 19-byte record.
  EXPECT_EQ(at<std::uint32_t>(bytes, bytes.size() - 4), 7u);
  EXPECT_EQ(at<std::uint32_t>(bytes, bytes.size() - 19 - 4), 3u);
  EXPECT_THROW(map_ply_bytes(parts, {"two\nlines"}), std::invalid_argument);
}

TEST(MapExport, LasOfAnEmptyMapIsAValidHeaderAndIdsBeyond16BitsAreRefused) {
  const std::string empty = map_las_bytes({}, 0);
  ASSERT_EQ(empty.size(), 375u);
  EXPECT_EQ(empty.substr(0, 4), "LASF");
  EXPECT_EQ(at<std::uint64_t>(empty, 247), 0u);
  EXPECT_EQ(at<std::uint16_t>(empty, 92), 1970u);  // creation year of time 0
  EXPECT_EQ(at<std::uint16_t>(empty, 90), 1u);     // day of year, from 1

  const std::string one = map_las_bytes({{65535, cloud({{0.0004f, -2.5f, 100}}, true)}}, 0);
  ASSERT_EQ(one.size(), 375u + 36u);
  EXPECT_EQ(at<std::uint16_t>(one, 375 + 20), 65535u);
  EXPECT_EQ(at<std::uint16_t>(one, 375 + 30), 10u * 257u);
  // Millimetres from the offset at the minimum corner in whole metres.
  EXPECT_DOUBLE_EQ(at<double>(one, 163), -3.0);
  EXPECT_EQ(at<std::int32_t>(one, 375 + 4), 500);
  EXPECT_EQ(at<std::int32_t>(one, 375 + 0), 0);
  EXPECT_THROW(map_las_bytes({{65536, cloud({{0, 0, 0}}, true)}}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace scanplan
