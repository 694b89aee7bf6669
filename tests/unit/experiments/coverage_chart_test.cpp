#include "scanplan/experiments/coverage_chart.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace scanplan {
namespace {

int pixels_of(const cv::Mat& img, const cv::Vec3b& bgr) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) n += img.at<cv::Vec3b>(y, x) == bgr;
  return n;
}

TEST(CoverageChart, DrawsTheMeanOfTheRunsInTheSeriesColour) {
  ChartStyle style;
  style.title = "coverage";
  style.references = {{95, "95 %"}};
  // Two runs of different lengths: the shorter one holds its last value.
  const ChartSeries a{"a", cv::Scalar(200, 0, 0), {{10, 50, 90}, {20, 60}}};
  const ChartSeries b{"b", cv::Scalar(0, 0, 200), {{5, 10, 15}}};
  const cv::Mat img = render_coverage_chart({a, b}, style);
  ASSERT_EQ(img.cols, style.width_px);
  ASSERT_EQ(img.rows, style.height_px);
  EXPECT_GT(pixels_of(img, {200, 0, 0}), 200);
  EXPECT_GT(pixels_of(img, {0, 0, 200}), 200);
  // Series a ends at the mean of 90 and 60 = 75 on a 0..100 axis, above b's 15: its colour
  // is found in the upper half of the last columns of the plot, b's only in the lower.
  const cv::Mat right = img.colRange(img.cols - 20, img.cols - 13);
  const cv::Mat upper = right.rowRange(0, img.rows / 2),
                lower = right.rowRange(img.rows / 2, img.rows);
  EXPECT_GT(pixels_of(upper, {200, 0, 0}), 0);
  EXPECT_EQ(pixels_of(upper, {0, 0, 200}), 0);
  EXPECT_GT(pixels_of(lower, {0, 0, 200}), 0);
}

TEST(CoverageChart, RefusesEmptyOrBrokenSeries) {
  EXPECT_THROW(render_coverage_chart({}, {}), std::invalid_argument);
  EXPECT_THROW(render_coverage_chart({{"x", cv::Scalar(0, 0, 0), {{}}}}, {}),
               std::invalid_argument);
  EXPECT_THROW(
      render_coverage_chart(
          {{"x", cv::Scalar(0, 0, 0), {{1, std::numeric_limits<double>::quiet_NaN()}}}}, {}),
      std::invalid_argument);
}

}  // namespace
}  // namespace scanplan
