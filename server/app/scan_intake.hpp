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

// Taking a scan out of the map or putting it back cannot be done: `code` says why (not_found,
// already_excluded, not_excluded, last_scan).
class ExclusionError : public std::runtime_error {
 public:
  ExclusionError(std::string code_, const std::string& message)
      : std::runtime_error(message), code(std::move(code_)) {}
  std::string code;
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

  // The operator takes scan `id` out of the map (`excluded`), or puts it back: recorded in the
  // session with who and why (the scan's file stays), published (scan_excluded /
  // scan_restored), and the map rebuilt without it (or with it) on the worker, after the scans
  // queued before. Returns the scan as it now stands. Thread-safe. Throws ExclusionError.
  StoredScan set_excluded(std::int64_t id, bool excluded, const std::string& by,
                          const std::string& reason);
  // The scans the operator keeps out of the map, in id order.
  std::vector<StoredScan> excluded_scans() const;

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
  // Brings one stored scan into the live map and tells the browsers; what the pose graph
  // changed is recorded and published unless `restoring` (a restart retracing the session).
  // `match_ms`: how long matching it took (wall clock, with the map's points gathered); none
  // for a scan brought back after a restart, which is not matched again.
  void process(const StoredScan& scan, const PointCloud& cloud, bool restoring = false,
               std::optional<double> match_ms = std::nullopt);
  // plan_done for each plan, by robot id, `first`'s first.
  void publish_plans(std::vector<PlanRecord> plans, const std::string& first);
  // A correction of the map: a revision of the poses in the session and `map_corrected`.
  void record_correction(const MapCorrected& corrected);
  // After a restart or a rebuild: records the poses where they differ from the session's latest
  // revision.
  void resume_poses();
  // A scan brought back within this of its recorded pose is where it was.
  static constexpr double kResumeToleranceM = 0.02;
  // Matches a new scan against the map so far (paper §4) and records where it goes.
  StoredScan match(StoredScan scan, const PointCloud& cloud);

  SessionStore& session_;
  LiveMap& live_;
  const Events& events_;
  mutable std::mutex mutex_;
  std::mutex exclusion_mutex_;  // one exclusion or restoration at a time, checked and recorded
  std::condition_variable wake_;
  // What the worker does next: a new scan into the map, or (no scan) a rebuild of the map from
  // the session's scans that are not excluded.
  struct Job {
    std::optional<StoredScan> scan;
    PointCloud cloud;
  };
  std::deque<Job> queue_;
  void rebuild_map();
  // A stored scan's points, without any that cannot be a measurement.
  PointCloud load(const StoredScan& scan) const;
  bool stop_ = false;
  std::vector<NotInMap> not_in_map_;
  std::optional<Rebuild> rebuild_;
  std::optional<StorageFailure> storage_failure_;
  std::thread worker_;
};

}  // namespace scanplan::server
