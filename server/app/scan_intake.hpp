#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "app/events.hpp"
#include "app/live_map.hpp"
#include "scanplan/geometry/scan_returns.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// The scan cannot join the map: too few of its points are measurements of the scene.
class UnusableScanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The scan's fields cannot be right: a pose that is no place (implausible_pose: 1e7 m out, a
// yaw of 10000°) or a robot id that is not one (robot_id_problem).
class InvalidScanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A scan accepted: as stored, and what was dropped from it on the way in.
struct SubmittedScan {
  StoredScan scan;
  DroppedReturns dropped;
};

// Where scans enter the session, from DDS or from POST /api/v1/scans. Each is first stored
// durably (that is what acknowledges it), then processed into the live map on a worker thread,
// so neither the network thread nor the DDS thread waits on the map, the layers or Draco.
class ScanIntake {
 public:
  // Fewer measurements than this are no scan: the matcher needs 30 after thinning to 0.25 m,
  // and a handful of points would enter the map as a scan that shows nothing.
  static constexpr std::size_t kMinScanPoints = 100;

  ScanIntake(SessionStore& session, LiveMap& live, const Events& events);
  ~ScanIntake();
  ScanIntake(const ScanIntake&) = delete;
  ScanIntake& operator=(const ScanIntake&) = delete;

  // Starts the worker, first bringing back every scan the session already holds. Call before
  // anything can submit.
  void start();
  void stop();

  // Thread-safe. Refuses an implausible pose or robot id (InvalidScanError), drops the returns that
  // are not the scene (NaNs, beyond the scanner's reach, its mount, a saturation shell:
  // drop_bad_returns; counted in the answer and the scan_received event) and refuses a scan
  // with fewer than kMinScanPoints left (UnusableScanError); a refusal is published as
  // scan_rejected, so that a scan lost on the DDS path is seen too. Returns once the scan is
  // on disk; throws SessionStoreError when it cannot be.
  SubmittedScan submit(const std::string& robot, const Pose& estimated, std::int64_t stamp_ns,
                       PointCloud cloud);
  // Scans stored but not yet in the live map.
  std::size_t pending() const;

  // A stored scan that is not in the map: on reopening the session its file was missing or
  // damaged or its stored pose no place, or the map could not take it.
  struct NotInMap {
    std::int64_t id = 0;
    std::string robot;
    std::string reason;
  };
  std::vector<NotInMap> not_in_map() const;
  // While a reopened session's scans are brought back into the map: how many of how many.
  struct Rebuild {
    std::size_t done = 0;
    std::size_t total = 0;
  };
  std::optional<Rebuild> rebuilding() const;
  // The last time the session could not be written after a scan was acknowledged (a full disk
  // losing a match's pose): the scan stays in the live map, the failure is shown here.
  struct StorageFailure {
    std::string at;  // UTC, ISO 8601
    std::string message;
  };
  std::optional<StorageFailure> last_storage_failure() const;

 private:
  void loop();
  // Brings one stored scan into the live map and tells the browsers.
  void process(const StoredScan& scan, const PointCloud& cloud);
  // Matches a new scan against the map so far (paper §4) and records where it goes.
  StoredScan match(StoredScan scan, const PointCloud& cloud);

  SessionStore& session_;
  LiveMap& live_;
  const Events& events_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::pair<StoredScan, PointCloud>> queue_;
  bool stop_ = false;
  std::vector<NotInMap> not_in_map_;
  std::optional<Rebuild> rebuild_;
  std::optional<StorageFailure> storage_failure_;
  std::thread worker_;
};

}  // namespace scanplan::server
