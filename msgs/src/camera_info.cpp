#include "scanplan/msgs/camera_info.hpp"

#include <cmath>

#include "scanplan/msgs/pointcloud2.hpp"

namespace scanplan::dds {

void to_camera_info(const PanoramaCamera& camera, const std::string& frame_id, std::int64_t stamp,
                    OwnedCameraInfo& out) {
  out.frame_id = frame_id;
  auto& m = out.msg;
  m = {};
  m.header.frame_id = out.frame_id.data();
  m.header.stamp = to_stamp(stamp);
  m.width = static_cast<std::uint32_t>(camera.width_px);
  m.height = static_cast<std::uint32_t>(camera.height_px);
  m.distortion_model = out.model.data();
  const double fx = camera.width_px / (2 * M_PI), fy = camera.height_px / M_PI;
  const double cx = camera.width_px / 2.0, cy = camera.height_px / 2.0;
  const double k[9] = {fx, 0, cx, 0, fy, cy, 0, 0, 1};
  std::copy(k, k + 9, m.k);
  const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::copy(r, r + 9, m.r);
  const double p[12] = {fx, 0, cx, camera.center_robot.x(), 0, fy, cy, camera.center_robot.y(),
                        0,  0, 1,  camera.center_robot.z()};
  std::copy(p, p + 12, m.p);
}

PanoramaCamera from_camera_info(const sensor_msgs_msg_dds__CameraInfo_& m) {
  const std::string model = m.distortion_model ? m.distortion_model : "";
  if (model != kEquirectangular) {
    throw CameraInfoError("camera model '" + model + "' is not supported (only '" +
                          kEquirectangular + "')");
  }
  if (m.width < 2 || m.height < 2 || m.width > 32768 || m.height > 16384) {
    throw CameraInfoError("camera size " + std::to_string(m.width) + "×" +
                          std::to_string(m.height) + " is not plausible");
  }
  const double fx = m.width / (2 * M_PI), fy = m.height / M_PI;
  if (std::abs(m.k[0] - fx) > 1e-6 * fx || std::abs(m.k[4] - fy) > 1e-6 * fy) {
    throw CameraInfoError("k does not describe a full 360° × 180° equirectangular panorama");
  }
  PanoramaCamera camera;
  camera.width_px = static_cast<int>(m.width);
  camera.height_px = static_cast<int>(m.height);
  camera.center_robot = {m.p[3], m.p[7], m.p[11]};
  if (!camera.center_robot.allFinite()) throw CameraInfoError("camera centre is not finite");
  return camera;
}

void OwnedCompressedImage::bind(std::int64_t stamp) {
  msg.header.frame_id = frame_id.data();
  msg.header.stamp = to_stamp(stamp);
  msg.format = format.data();
  msg.data._buffer = data.data();
  msg.data._length = msg.data._maximum = static_cast<std::uint32_t>(data.size());
  msg.data._release = false;
}

}  // namespace scanplan::dds
