#pragma once

#include <opencv2/core.hpp>

#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/sim/ray_caster.hpp"

namespace scanplan {

// Simple daylight shading: a sun, an ambient term and a sky colour where rays hit nothing.
struct Shading {
  Eigen::Vector3d sun_dir{0.45, 0.3, 0.84};  // towards the sun, world frame
  double ambient = 0.45;
  double diffuse = 0.55;
  Rgb sky{170, 200, 235};
  double max_range_m = 300.0;
};

// Renders what the panorama camera sees at `true_pose` in the simulated world (BGR, 8 bit).
cv::Mat render_panorama(const RayCaster& caster, const PanoramaCamera& camera,
                        const Pose& true_pose, const Shading& shading = {});

}  // namespace scanplan
