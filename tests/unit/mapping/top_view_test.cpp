#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mapping_test_support.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/mapping/top_view.hpp"

namespace scanplan {
namespace {

using test::slab;

TEST(TopView, LayersHaveTheTargetsShapeAndColours) {
  MlsMap map;
  map.insert(slab(0, 30, 0, 10, 0.0f));
  const RegionMap r = segment_regions(map, TargetRegion::rectangle({0, 0}, {40, 10}), {{0.5, 0.5}});
  const MovableRegion m = movable_region(map, {0.5, 0.5, 0.0});
  TopViewStyle style;
  style.px_per_cell = 2;
  const cv::Mat img = render_regions(r, &m, {{0.5, 0.5}}, style);
  EXPECT_EQ(img.cols, r.cells.cols * 2);
  EXPECT_EQ(img.rows, r.cells.rows * 2);
  // Cell (25, 5): low resolution and movable → yellow (BGR 64, 208, 236); north is up.
  const cv::Vec3b px = img.at<cv::Vec3b>((r.cells.rows - 1 - 5) * 2, 25 * 2);
  EXPECT_EQ(px, cv::Vec3b(64, 208, 236));
  const auto png = encode_png(render_elevation(map, r, style));
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
  EXPECT_EQ(encode_png(render_movable(map, m, r, style))[2], 'N');
}

// The elevation view's colour scale spans the target's lowest and highest top surface: a 2 m step
// inside the target counts, one outside it does not, and an empty map has no scale.
TEST(TopView, TheElevationScaleSpansTheTargetsSurfaces) {
  MlsMap map;
  map.insert(slab(0, 20, 0, 10, 0.0f));
  map.insert(slab(20, 30, 0, 10, 2.0f));
  map.insert(slab(60, 70, 0, 10, 9.0f));
  const RegionMap r = segment_regions(map, TargetRegion::rectangle({0, 0}, {40, 10}), {{0.5, 0.5}});
  const auto range = elevation_range(map, r);
  ASSERT_TRUE(range);
  EXPECT_NEAR(range->lo, 0.0f, 0.05f);
  EXPECT_NEAR(range->hi, 2.0f, 0.05f);
  EXPECT_FALSE(elevation_range(MlsMap{}, r));
}

TEST(TopView, ACaptionedViewKeepsTheMapAndAddsTitleLegendAndScale) {
  MlsMap map;
  map.insert(slab(0, 30, 0, 10, 0.0f));
  const RegionMap r =
      segment_regions(map, TargetRegion::rectangle({0, 0}, {200, 40}), {{0.5, 0.5}});
  const cv::Mat view = render_regions(r, nullptr, {{0.5, 0.5}});
  const cv::Mat out = captioned_regions(view, r, "campus, scan 3");
  ASSERT_GE(out.cols, view.cols);
  EXPECT_GT(out.rows, view.rows + 3 * 28) << "a title band, a legend and a scale bar";
  // The map itself is there untouched, below the title band.
  cv::Mat diff;
  cv::absdiff(out(cv::Rect(0, 28, view.cols, view.rows)), view, diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
  // The bands are written on (text and swatches), not left blank.
  const cv::Mat title = out(cv::Rect(0, 0, out.cols, 28));
  cv::Mat grey;
  cv::cvtColor(title, grey, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(grey > 200), 50);
}

}  // namespace
}  // namespace scanplan
