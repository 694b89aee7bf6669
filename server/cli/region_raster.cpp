#include "region_raster.hpp"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace scanplan::cli {
namespace {

// The fills of core/mapping/src/top_view.cpp (BGR). PNG is lossless, so an undrawn pixel has
// exactly one of these; anti-aliased edges of drawings match none and are left out of the counts.
struct Fill {
  std::uint8_t b, g, r;
  RegionClass cls;
};
constexpr Fill kFills[] = {
    {24, 20, 20, RegionClass::kOutside},         {64, 64, 64, RegionClass::kUnscanned},
    {180, 214, 250, RegionClass::kCompleted},    {64, 208, 236, RegionClass::kLowMovable},
    {200, 110, 70, RegionClass::kLowNotMovable},
};

}  // namespace

RegionRaster decode_regions_png(const std::string& png, double target_min_x, double target_min_y,
                                double target_max_x, double target_max_y, double cell_m,
                                int px_per_cell) {
  cv::Mat img;
  if (!png.empty()) {
    const cv::Mat bytes(1, static_cast<int>(png.size()), CV_8U,
                        const_cast<char*>(png.data()));  // imdecode only reads
    try {
      img = cv::imdecode(bytes, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      img.release();  // reported below as any undecodable answer
    }
  }
  if (img.empty()) throw std::runtime_error("the regions layer is not a PNG image");
  // The grid of region_segmentation.cpp: cells from floor(min / cell) to floor(max / cell).
  const double x0 = std::floor(target_min_x / cell_m), y0 = std::floor(target_min_y / cell_m);
  const int cols = static_cast<int>(std::floor(target_max_x / cell_m) - x0) + 1;
  const int rows = static_cast<int>(std::floor(target_max_y / cell_m) - y0) + 1;
  if (img.cols != cols * px_per_cell || img.rows != rows * px_per_cell) {
    throw std::runtime_error("the regions layer is " + std::to_string(img.cols) + "x" +
                             std::to_string(img.rows) + " px but the target region spans " +
                             std::to_string(cols) + "x" + std::to_string(rows) +
                             " cells; it may have changed in between, try again");
  }
  RegionRaster out;
  out.width = img.cols;
  out.height = img.rows;
  out.m_per_px = cell_m / px_per_cell;
  out.x_min = x0 * cell_m;
  out.y_max = (y0 + rows) * cell_m;
  out.pixels.resize(static_cast<std::size_t>(img.cols) * static_cast<std::size_t>(img.rows),
                    RegionClass::kUnknown);
  for (int row = 0; row < img.rows; ++row) {
    const auto* p = img.ptr<cv::Vec3b>(row);
    for (int col = 0; col < img.cols; ++col) {
      for (const Fill& f : kFills) {
        if (p[col][0] == f.b && p[col][1] == f.g && p[col][2] == f.r) {
          out.pixels[static_cast<std::size_t>(row) * static_cast<std::size_t>(img.cols) +
                     static_cast<std::size_t>(col)] = f.cls;
          break;
        }
      }
    }
  }
  return out;
}

}  // namespace scanplan::cli
