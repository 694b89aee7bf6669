#include <gtest/gtest.h>

#include "scanplan/io/image_codec.hpp"
#include "scanplan/mapping/colorizer.hpp"
#include "scanplan/sim/panorama_renderer.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

World coloured_world() {
  return parse_world(R"({"name": "colours", "bounds": {"min": [-20, -20], "max": [20, 20]},
      "ground": {"z": 0, "color": [60, 160, 60]},
      "objects": [
        {"type": "box", "min": [4, -3, 0], "max": [6, 3, 3], "color": [220, 40, 40]},
        {"type": "box", "min": [-8, -2, 0], "max": [-7, 5, 5], "color": [40, 60, 220]},
        {"type": "box", "min": [-2, 6, 0], "max": [3, 7, 2], "color": [230, 200, 40]}
      ],
      "start": [0, 0, 0], "pose_noise": {"model": "absolute", "xy_sigma_m": 0, "z_sigma_m": 0, "yaw_sigma_deg": 0}})",
                     "colours.json");
}

Eigen::Vector3d chroma(const Rgb& c) {
  const double sum = double(c[0]) + c[1] + c[2] + 1e-9;
  return {c[0] / sum, c[1] / sum, c[2] / sum};
}

TEST(PanoramaCamera, ProjectionInvertsPixelDirection) {
  const PanoramaCamera cam;
  for (double u : {0.5, 100.25, 511.5, 900.0}) {
    for (double v : {1.0, 128.5, 400.0}) {
      const Eigen::Vector2d px = cam.project_direction(cam.pixel_direction(u, v));
      EXPECT_NEAR(px.x(), u, 1e-9);
      EXPECT_NEAR(px.y(), v, 1e-9);
    }
  }
  // Straight ahead is the image centre; left of the robot is left in the image.
  EXPECT_NEAR(cam.project_direction({1, 0, 0}).x(), cam.width_px / 2.0, 1e-9);
  EXPECT_LT(cam.project_direction({1, 1, 0}).x(), cam.width_px / 2.0);
}

// Each point takes the camera's colour of the surface the laser hit: shading scales a colour's
// brightness, so compare chromaticity with the surface's own colour.
TEST(Colorizer, PointsTakeTheColourOfTheSurfaceTheyLieOn) {
  World w = coloured_world();
  w.scanner.rotation_step_deg = 2;
  w.scanner.vertical_step_deg = 1;
  const RayCaster caster(w);
  PointCloud cloud = simulate_scan(caster, w.scanner, w.start, 5);
  const PointCloud truth = cloud;
  const PanoramaCamera camera = PanoramaCamera::for_scanner(w.scanner);
  const cv::Mat image = decode_image(encode_jpeg(render_panorama(caster, camera, w.start), 90));
  ASSERT_EQ(image.cols, camera.width_px);

  const ColorizeStats stats = colorize(cloud, image, camera);
  EXPECT_EQ(stats.colored + stats.occluded, cloud.size());
  EXPECT_LT(stats.occluded, cloud.size() / 50) << "few points are hidden from a camera 15 cm up";
  std::size_t close = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    close += (chroma(cloud.colors[i]) - chroma(truth.colors[i])).norm() < 0.06;
  }
  EXPECT_GT(close, cloud.size() * 95 / 100) << close << " of " << cloud.size();
}

TEST(Colorizer, PointHiddenBehindANearerSurfaceIsNotColoured) {
  PanoramaCamera camera;
  camera.width_px = 64;
  camera.height_px = 32;
  camera.center_robot = {0, 0, 1};
  PointCloud cloud;
  cloud.push_back({2, 0, 1}, {});   // a near surface straight ahead
  cloud.push_back({10, 0, 1}, {});  // a far one in the same pixel
  cv::Mat image(32, 64, CV_8UC3, cv::Scalar(10, 20, 30));
  const ColorizeStats stats = colorize(cloud, image, camera);
  EXPECT_EQ(stats.colored, 1u);
  EXPECT_EQ(stats.occluded, 1u);
  EXPECT_EQ(cloud.colors[0], (Rgb{30, 20, 10}));
  EXPECT_EQ(cloud.colors[1], ColorizeOptions{}.unseen);
}

TEST(Colorizer, ImageOfTheWrongSizeIsRefused) {
  PanoramaCamera camera;
  PointCloud cloud;
  cloud.push_back({1, 0, 0}, {});
  EXPECT_THROW(colorize(cloud, cv::Mat(10, 10, CV_8UC3), camera), std::invalid_argument);
}

TEST(ImageCodec, GarbageIsNoImage) {
  const std::vector<std::uint8_t> junk{1, 2, 3, 4, 5};
  EXPECT_THROW(decode_image(junk), ImageCodecError);
  EXPECT_THROW(decode_image({}), ImageCodecError);
}

}  // namespace
}  // namespace scanplan
