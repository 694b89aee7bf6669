// The ASCII top view of `scanplan candidates`: decoding the server's regions layer (drawn here
// by scanplan_core's own renderer) and drawing it with markers from fixed inputs.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "ascii_top_view.hpp"
#include "region_raster.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/mapping/top_view.hpp"
#include "scanplan/planning/plan_view.hpp"

namespace scanplan::cli {
namespace {

// A 10 m x 6 m target region from (-5, -3), 1 m cells: the western half completed, then a
// column of low-resolution cells that are movable and one that is not, the rest unscanned, and
// the north-east corner cell outside the (polygonal) target.
RegionMap sample_regions() {
  RegionMap r;
  r.cells = CellGrid<Region>({-5, -3}, 10, 6, 1.0, Region::kUnscanned);
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 10; ++i) {
      Region& v = r.cells.values[static_cast<std::size_t>(j) * 10 + i];
      if (i < 5) v = Region::kCompleted;
      if (i == 5 || i == 6) v = Region::kLowResolution;
      if (i == 9 && j == 5) v = Region::kOutside;
    }
  }
  return r;
}

MovableRegion column_five_movable() {
  MovableRegion m;
  m.patch = CellGrid<std::int8_t>({-5, -3}, 10, 6, 1.0, -1);
  for (int j = 0; j < 6; ++j) m.patch.values[static_cast<std::size_t>(j) * 10 + 5] = 0;
  m.cells = 6;
  return m;
}

std::string png_of(const cv::Mat& img) {
  const auto bytes = encode_png(img);
  return std::string(bytes.begin(), bytes.end());
}

TEST(RegionRaster, DecodesTheServersColoursAndGeoreferencesThem) {
  const RegionMap regions = sample_regions();
  const MovableRegion movable = column_five_movable();
  const RegionRaster r =
      decode_regions_png(png_of(render_regions(regions, &movable, {})), -5, -3, 4.5, 2.5);
  ASSERT_EQ(r.width, 40);
  ASSERT_EQ(r.height, 24);
  EXPECT_DOUBLE_EQ(r.x_min, -5);
  EXPECT_DOUBLE_EQ(r.y_max, 3);
  EXPECT_DOUBLE_EQ(r.m_per_px, 0.25);
  // Row 0 is the north edge (y = 3), the cell row j = 5.
  EXPECT_EQ(r.at(1, 1), RegionClass::kCompleted);
  EXPECT_EQ(r.at(5 * 4 + 1, 1), RegionClass::kLowMovable);
  EXPECT_EQ(r.at(6 * 4 + 1, 1), RegionClass::kLowNotMovable);
  EXPECT_EQ(r.at(8 * 4 + 1, 1), RegionClass::kUnscanned);
  EXPECT_EQ(r.at(9 * 4 + 1, 1), RegionClass::kOutside);
  EXPECT_EQ(r.at(9 * 4 + 1, 5), RegionClass::kUnscanned) << "one cell row further south";
}

TEST(RegionRaster, DrawingsOverTheMapAreUnknownNotGuessed) {
  const RegionMap regions = sample_regions();
  cv::Mat img = render_regions(regions, nullptr, {Eigen::Vector2d(-2.5, 0.5)});
  Candidate c;
  c.position = Eigen::Vector3d(3.5, -1.5, 0);
  draw_plan(img, regions, {c}, std::nullopt);
  const RegionRaster r = decode_regions_png(png_of(img), -5, -3, 4.5, 2.5);
  // The scan point's filled circle covers its centre pixel: (-2.5, 0.5) is column 10, row 10.
  EXPECT_EQ(r.at(10, 10), RegionClass::kUnknown);
  std::size_t unknown = 0;
  for (RegionClass v : r.pixels) unknown += v == RegionClass::kUnknown;
  EXPECT_GT(unknown, 0u);
  // On this 10 m map the 2 m scan-point disc and the ring take a good share; not all of it.
  EXPECT_LT(unknown, r.pixels.size() / 2);
}

TEST(RegionRaster, RefusesAnImageThatDoesNotFitTheTargetRegion) {
  const std::string png = png_of(render_regions(sample_regions(), nullptr, {}));
  EXPECT_THROW(decode_regions_png(png, -5, -3, 14.5, 2.5), std::runtime_error);
  EXPECT_THROW(decode_regions_png("not a png", -5, -3, 4.5, 2.5), std::runtime_error);
}

// A raster drawn by hand: 8 m x 4 m at 1 px a metre, west half completed, east half unscanned.
RegionRaster half_and_half() {
  RegionRaster r;
  r.width = 8;
  r.height = 4;
  r.x_min = 0;
  r.y_max = 4;
  r.m_per_px = 1;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 8; ++col) {
      r.pixels.push_back(col < 4 ? RegionClass::kCompleted : RegionClass::kUnscanned);
    }
  }
  return r;
}

TEST(AsciiTopView, DrawsRegionsMarkersHeaderAndLegend) {
  const RegionRaster raster = half_and_half();
  TopViewInput in;
  in.min_x = 0;
  in.min_y = 0;
  in.max_x = 8;
  in.max_y = 4;
  in.regions = &raster;
  in.scan_points = {{0.5, 3.5}, {2.5, 0.5}};
  in.robots = {{2.5, 0.5}};
  in.candidates = {{2, 6.5, 3.5}, {1, 7.5, 0.5}};
  // 8 columns of 1 m and, with square characters, 4 rows of 1 m.
  const auto lines = render_ascii_top_view(in, {8, 4, 1.0});
  const std::vector<std::string> expected = {
      "north up; x 0..8 m, y 0..4 m; 1 char = 1.0 m x 1.0 m",
      "+--------+",
      "|o###..2.|",
      "|####....|",
      "|####....|",
      "|##R#...1|",
      "+--------+",
      "# completed  + low-res, drivable  = low-res, not drivable  . unscanned",
      "o scan point  R robot  1-9 candidates by rank",
  };
  EXPECT_EQ(lines, expected);
}

TEST(AsciiTopView, KeepsTheShapeOnTallTerminalCells) {
  TopViewInput in;
  in.max_x = 200;
  in.max_y = 200;
  // 200 m square in at most 60 x 20 characters twice as tall as wide: 5 m a column, 10 m a row.
  const auto lines = render_ascii_top_view(in, {60, 20, 2.0});
  EXPECT_EQ(lines[0], "north up; x 0..200 m, y 0..200 m; 1 char = 5.0 m x 10.0 m");
  EXPECT_EQ(lines[1].size(), 42u);
  EXPECT_EQ(lines.size(), 1u + 2 + 20 + 2);
}

TEST(AsciiTopView, TheBetterRankWinsASharedCharacterAndHighRanksUseLetters) {
  TopViewInput in;
  in.max_x = 4;
  in.max_y = 1;
  in.candidates = {{1, 0.2, 0.5}, {3, 0.4, 0.5}, {12, 2.5, 0.5}, {40, 3.5, 0.5}};
  const auto lines = render_ascii_top_view(in, {4, 1, 1.0});
  EXPECT_EQ(lines[2], "|1 C*|");
  EXPECT_EQ(lines.back(), "o scan point  R robot  1-9 candidates by rank, A-Z ranks 10-35");
}

TEST(AsciiTopView, MarkersOutsideTheAreaAreLeftOutAndUnknownIsMarked) {
  RegionRaster r;
  r.width = 2;
  r.height = 1;
  r.y_max = 1;
  r.m_per_px = 1;
  r.pixels = {RegionClass::kUnknown, RegionClass::kLowNotMovable};
  TopViewInput in;
  in.max_x = 2;
  in.max_y = 1;
  in.regions = &r;
  in.robots = {{-10, 0}, {5, 5}};
  const auto lines = render_ascii_top_view(in, {2, 1, 1.0});
  EXPECT_EQ(lines[2], "|?=|");
  EXPECT_NE(lines[4].find("? under drawings"), std::string::npos) << lines[4];
}

TEST(AsciiTopView, ZoomsToWhereThereIsSomethingWithAMargin) {
  RegionRaster r;
  r.width = 100;
  r.height = 100;
  r.x_min = -50;
  r.y_max = 50;
  r.m_per_px = 1;
  r.pixels.assign(100 * 100, RegionClass::kUnscanned);
  r.pixels[50 * 100 + 50] = RegionClass::kCompleted;  // the cell x 0..1, y -1..0
  TopViewInput in;
  in.min_x = -50;
  in.min_y = -50;
  in.max_x = 50;
  in.max_y = 50;
  in.regions = &r;
  in.candidates = {{1, 10, 10}};
  zoom_to_known_area(in, 5);
  EXPECT_DOUBLE_EQ(in.min_x, -5);
  EXPECT_DOUBLE_EQ(in.max_x, 15);
  EXPECT_DOUBLE_EQ(in.min_y, -6);
  EXPECT_DOUBLE_EQ(in.max_y, 15);

  TopViewInput nothing;
  nothing.max_x = nothing.max_y = 100;
  zoom_to_known_area(nothing, 5);
  EXPECT_DOUBLE_EQ(nothing.max_x, 100) << "nothing known: the whole area";

  TopViewInput edge;
  edge.max_x = edge.max_y = 100;
  edge.scan_points = {{1, 1}};
  zoom_to_known_area(edge, 5);
  EXPECT_DOUBLE_EQ(edge.min_x, 0) << "never beyond the area";
}

}  // namespace
}  // namespace scanplan::cli
