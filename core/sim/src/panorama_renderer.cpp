#include "scanplan/sim/panorama_renderer.hpp"

#include <algorithm>

namespace scanplan {

cv::Mat render_panorama(const RayCaster& caster, const PanoramaCamera& camera,
                        const Pose& true_pose, const Shading& shading) {
  cv::Mat image(camera.height_px, camera.width_px, CV_8UC3);
  const Eigen::Isometry3d world_from_robot = true_pose.isometry();
  const Eigen::Vector3d origin = world_from_robot * camera.center_robot;
  const Eigen::Vector3d sun = shading.sun_dir.normalized();
#pragma omp parallel for schedule(dynamic, 8)
  for (int v = 0; v < camera.height_px; ++v) {
    auto* row = image.ptr<cv::Vec3b>(v);
    for (int u = 0; u < camera.width_px; ++u) {
      const Eigen::Vector3d dir =
          world_from_robot.linear() * camera.pixel_direction(u + 0.5, v + 0.5);
      const auto hit = caster.cast(origin, dir, 0.0, shading.max_range_m);
      Rgb c = shading.sky;
      if (hit) {
        const double lambert = std::max(0.0, hit->normal.cast<double>().dot(sun));
        const double k = shading.ambient + shading.diffuse * lambert;
        for (int i = 0; i < 3; ++i)
          c[i] = static_cast<std::uint8_t>(std::min(255.0, hit->color[i] * k));
      }
      row[u] = cv::Vec3b(c[2], c[1], c[0]);
    }
  }
  return image;
}

}  // namespace scanplan
