#include "scanplan/mapping/colorizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace scanplan {
namespace {

// Bilinear sample with wrap-around in u (the panorama's seam) and clamping in v.
Rgb sample(const cv::Mat& img, double u, double v) {
  const double x = u - 0.5, y = std::clamp(v - 0.5, 0.0, img.rows - 1.0);
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const int y1 = std::min(y0 + 1, img.rows - 1);
  const auto wrap = [&](int c) { return ((c % img.cols) + img.cols) % img.cols; };
  const cv::Vec3b& a = img.at<cv::Vec3b>(y0, wrap(x0));
  const cv::Vec3b& b = img.at<cv::Vec3b>(y0, wrap(x0 + 1));
  const cv::Vec3b& c = img.at<cv::Vec3b>(y1, wrap(x0));
  const cv::Vec3b& d = img.at<cv::Vec3b>(y1, wrap(x0 + 1));
  Rgb out;
  for (int ch = 0; ch < 3; ++ch) {
    const double top = a[ch] * (1 - fx) + b[ch] * fx;
    const double bottom = c[ch] * (1 - fx) + d[ch] * fx;
    out[2 - ch] = static_cast<std::uint8_t>(std::lround(top * (1 - fy) + bottom * fy));
  }
  return out;
}

}  // namespace

ColorizeStats colorize(PointCloud& cloud, const cv::Mat& image_bgr, const PanoramaCamera& camera,
                       const ColorizeOptions& options) {
  if (image_bgr.type() != CV_8UC3 || image_bgr.empty()) {
    throw std::invalid_argument("colourisation needs an 8-bit, 3-channel image");
  }
  if (image_bgr.cols != camera.width_px || image_bgr.rows != camera.height_px) {
    throw std::invalid_argument("the image is " + std::to_string(image_bgr.cols) + "×" +
                                std::to_string(image_bgr.rows) + " but its calibration says " +
                                std::to_string(camera.width_px) + "×" +
                                std::to_string(camera.height_px));
  }
  const int cell = std::max(1, options.depth_cell_px);
  const int dw = (camera.width_px + cell - 1) / cell, dh = (camera.height_px + cell - 1) / cell;
  std::vector<float> depth(static_cast<std::size_t>(dw) * dh,
                           std::numeric_limits<float>::infinity());
  std::vector<Eigen::Vector2d> pixel(cloud.size());
  std::vector<float> range(cloud.size());
  const auto cell_of = [&](const Eigen::Vector2d& px) {
    const int cu = std::clamp(static_cast<int>(px.x()) / cell, 0, dw - 1);
    const int cv = std::clamp(static_cast<int>(px.y()) / cell, 0, dh - 1);
    return static_cast<std::size_t>(cv) * dw + cu;
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto px = camera.project(cloud.points[i]);
    pixel[i] = px.value_or(Eigen::Vector2d(-1, -1));
    range[i] = static_cast<float>((cloud.points[i].cast<double>() - camera.center_robot).norm());
    if (px) depth[cell_of(*px)] = std::min(depth[cell_of(*px)], range[i]);
  }
  cloud.colors.resize(cloud.size());
  ColorizeStats stats;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (pixel[i].x() < 0) {
      cloud.colors[i] = options.unseen;
      continue;
    }
    const float nearest = depth[cell_of(pixel[i])];
    if (range[i] > nearest + options.occlusion_abs_m + options.occlusion_rel * nearest) {
      cloud.colors[i] = options.unseen;
      ++stats.occluded;
      continue;
    }
    cloud.colors[i] = sample(image_bgr, pixel[i].x(), pixel[i].y());
    ++stats.colored;
  }
  return stats;
}

}  // namespace scanplan
