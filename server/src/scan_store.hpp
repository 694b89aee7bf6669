#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "scanplan/core/mapping_pipeline.hpp"
#include "scanplan/core/point_cloud.hpp"
#include "scanplan/core/pose.hpp"
#include "scanplan/core/session_store.hpp"

namespace scanplan::server {

// What the session knows of one robot's current scan.
struct RobotScanState {
  std::uint32_t command_id = 0;
  std::string state = "idle";  // idle, scanning, done, failed
  float fraction = 0;
  std::string message;
};

// What the robot last said about itself (scanplan_RobotStatus).
struct RobotStatus {
  std::uint32_t command_id = 0;
  std::string state = "unknown";  // idle, moving, arrived, refused, scanning
  std::string message;
  Pose reported;
};

struct RobotState {
  RobotStatus status;
  RobotScanState scan;
};

// Areas of the target region's C / M / U segmentation and of the movable region (m²).
struct MapAreas {
  double completed_m2 = 0, low_resolution_m2 = 0, unscanned_m2 = 0, movable_m2 = 0;
};

// The scans of this session, in the map frame, with what is derived from them: the map's Draco
// encoding, the MLS map with its regions, and the top-view layers as PNG. All of it is rebuilt
// off the network thread each time a scan lands, so serving never waits on an encoder.
class ScanStore {
 public:
  explicit ScanStore(PipelineConfig pipeline = {});

  // A stored scan joins the map: `cloud` is in the scan's own frame, `scan.placed` puts it in
  // the map frame. Scans must come in id order.
  void add(const StoredScan& scan, const PointCloud& cloud);

  std::vector<StoredScan> scans() const;
  std::size_t scan_count() const;
  std::size_t point_count() const;
  Bounds3 bounds() const;
  // Null while the map is empty.
  std::shared_ptr<const std::string> encoded_map() const;
  // A top-view layer as PNG: "regions", "elevation" or "movable"; null before the first scan.
  std::shared_ptr<const std::vector<std::uint8_t>> layer_png(const std::string& name) const;
  static const std::vector<std::string>& layer_names();
  MapAreas areas() const;

  void set_scan_state(const std::string& robot_id, RobotScanState state);
  void set_robot_status(const std::string& robot_id, RobotStatus status);
  std::map<std::string, RobotState> robot_states() const;

 private:
  mutable std::mutex mutex_;
  std::vector<StoredScan> scans_;
  PointCloud map_;
  std::shared_ptr<const std::string> encoded_;
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> layers_;
  MapAreas areas_;
  MappingPipeline pipeline_;  // written only under encode_mutex_
  std::map<std::string, RobotState> robots_;
  std::mutex encode_mutex_;  // one encoder run at a time; readers keep the previous result
};

}  // namespace scanplan::server
