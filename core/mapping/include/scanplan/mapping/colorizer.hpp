#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

struct ColorizeOptions {
  // A point farther than the nearest surface the camera sees along its pixel, by more than
  // abs + rel × distance, is hidden from the camera (laser and camera centres differ).
  // The relative part covers ground seen at grazing angles, whose range changes fast across
  // one pixel.
  double occlusion_abs_m = 0.2;
  double occlusion_rel = 0.1;
  // The depth buffer is built from the laser points themselves. Coarser cells close the gaps
  // between laser samples through which a hidden point could show, but also mix ranges of
  // steep surfaces; one pixel is the safe default at the laser's 0.5° spacing.
  int depth_cell_px = 1;
  Rgb unseen{128, 128, 128};  // for points the camera did not see
};

struct ColorizeStats {
  std::size_t colored = 0;
  std::size_t occluded = 0;
};

// Gives each point of `cloud` (robot frame) the colour of its projection into `image_bgr`, the
// panorama taken with `camera`; points the camera could not see get `options.unseen`.
ColorizeStats colorize(PointCloud& cloud, const cv::Mat& image_bgr, const PanoramaCamera& camera,
                       const ColorizeOptions& options = {});

}  // namespace scanplan
