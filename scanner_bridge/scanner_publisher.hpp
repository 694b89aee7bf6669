#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::bridge {

// A panorama as the camera delivers it: JPEG bytes plus the calibration to project into it.
struct CameraShot {
  std::vector<std::uint8_t> jpeg;
  PanoramaCamera camera;
};

// Everything a robot says on DDS, whatever stands behind it (simulator or recorded scans).
class ScannerPublisher {
 public:
  ScannerPublisher(dds::Participant& participant, std::string robot_id);

  const std::string& robot_id() const { return robot_id_; }
  void progress(std::uint32_t command_id, const std::string& state, float fraction,
                const std::string& message = "");
  void status(std::uint32_t command_id, const std::string& state, const Pose& reported,
              const std::string& message = "");
  // The last status before the bridge stops: the server then reports the robot lost at once and
  // as shut down, where otherwise it could only see the writers vanish (as when killed).
  void goodbye(const Pose& reported);
  // Camera first, then pose, then points, all with one stamp: the server pairs them by it and
  // colourises when the image is there before the points.
  void scan(const PointCloud& cloud_robot_frame, const Pose& reported,
            const std::optional<CameraShot>& shot);

 private:
  std::string robot_id_;
  dds_entity_t points_, pose_, image_, camera_info_, progress_, status_;
};

}  // namespace scanplan::bridge
