#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan::server {

// One scan as it came from its robot: points (scanner frame), the pose the robot estimated,
// and its panorama with the camera's calibration when they came.
struct AssembledScan {
  std::string robot;
  std::int64_t stamp_ns = 0;
  PointCloud points;
  Pose pose;
  std::optional<std::vector<std::uint8_t>> jpeg;
  std::optional<PanoramaCamera> camera;
};

// A scan travels on four DDS topics (points, pose, panorama, calibration) that arrive in any
// order, keyed by robot and stamp: this gathers the parts into whole scans. Pure bookkeeping,
// no DDS: the link feeds it the samples it took and a clock reading.
class ScanAssembly {
 public:
  using Clock = std::chrono::steady_clock;
  using Key = std::pair<std::string, std::int64_t>;  // robot id, stamp (ns)

  struct Config {
    // A scan whose panorama does not come (a robot without a camera, a lost image) is stored
    // uncoloured after this long.
    Clock::duration image_wait = std::chrono::seconds(2);
    // A scan whose other parts never come (a bridge that died between writes) is dropped after
    // this long, and at most this many are held, so they cannot pin memory for the session.
    Clock::duration expiry = std::chrono::seconds(60);
    std::size_t max_open = 8;
    // Scans discarded with their bridge, remembered so that a part still in flight (a link that
    // came back) cannot start the scan over; a handful covers every scan a robot can have open.
    std::size_t max_discarded = 32;
  };

  ScanAssembly() : ScanAssembly(Config{}) {}
  explicit ScanAssembly(Config config) : config_(config) {}

  // Each part joins its scan; false when that scan was discarded with its bridge.
  bool add_points(const Key& key, PointCloud points, Clock::time_point now);
  bool add_pose(const Key& key, const Pose& pose, Clock::time_point now);
  bool add_image(const Key& key, std::vector<std::uint8_t> jpeg, Clock::time_point now);
  bool add_camera(const Key& key, const PanoramaCamera& camera, Clock::time_point now);

  // An incomplete scan given up on: which parts it had.
  struct Dropped {
    Key key;
    bool had_points = false, had_pose = false;
  };
  struct Taken {
    std::vector<AssembledScan> complete;  // points and pose in, and the panorama or its wait over
    std::vector<Dropped> dropped;         // expired, or over max_open (the oldest key first)
  };
  Taken take(Clock::time_point now);

  // Drops every open scan of `robot` for good; returns how many parts had arrived.
  std::size_t discard(const std::string& robot);
  std::size_t open_scans() const { return open_.size(); }

 private:
  struct Parts {
    std::optional<PointCloud> points;
    std::optional<Pose> pose;
    std::optional<std::vector<std::uint8_t>> jpeg;
    std::optional<PanoramaCamera> camera;
    Clock::time_point first_seen;
  };
  // The open scan `key`, started at `now` if new; null for a discarded one.
  Parts* parts(const Key& key, Clock::time_point now);

  Config config_;
  std::map<Key, Parts> open_;
  std::deque<Key> discarded_;
};

}  // namespace scanplan::server
