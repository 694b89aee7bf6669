#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ros2_types.h"
#include "scanplan/geometry/panorama_camera.hpp"

namespace scanplan::dds {

class CameraInfoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The panorama's calibration in a CameraInfo: distortion_model "equirectangular";
// k = [fx 0 cx; 0 fy cy; 0 0 1] with u = cx − fx·azimuth, v = cy − fy·elevation (radians,
// robot axes); p's last column holds the optical centre in the robot frame (metres), since an
// equirectangular camera has no projection matrix for it to mean anything else.
inline constexpr const char* kEquirectangular = "equirectangular";

struct OwnedCameraInfo {
  std::string frame_id;
  std::string model = kEquirectangular;
  sensor_msgs_msg_dds__CameraInfo_ msg{};
};

void to_camera_info(const PanoramaCamera& camera, const std::string& frame_id,
                    std::int64_t stamp_ns, OwnedCameraInfo& out);
// Throws CameraInfoError for a model other than equirectangular or inconsistent numbers.
PanoramaCamera from_camera_info(const sensor_msgs_msg_dds__CameraInfo_& msg);

// A CompressedImage sample that owns its bytes.
struct OwnedCompressedImage {
  std::string frame_id;
  std::string format = "jpeg";
  std::vector<std::uint8_t> data;
  sensor_msgs_msg_dds__CompressedImage_ msg{};
  // Points the message at the owned strings and bytes; call after filling them.
  void bind(std::int64_t stamp_ns);
};

}  // namespace scanplan::dds
