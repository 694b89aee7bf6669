#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "app/events.hpp"
#include "app/live_map.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// A scan in which nothing is left once the returns that are not the scene are dropped
// (drop_bad_returns): nothing to store.
class UnusableScanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where scans enter the session, from DDS or from POST /api/v1/scans. Each is first stored
// durably (that is what acknowledges it), then processed into the live map on a worker thread,
// so neither the network thread nor the DDS thread waits on the map, the layers or Draco.
class ScanIntake {
 public:
  ScanIntake(SessionStore& session, LiveMap& live, const Events& events);
  ~ScanIntake();
  ScanIntake(const ScanIntake&) = delete;
  ScanIntake& operator=(const ScanIntake&) = delete;

  // Starts the worker, first bringing back every scan the session already holds. Call before
  // anything can submit.
  void start();
  void stop();

  // Thread-safe. Drops the returns that are not the scene first (NaNs, the scanner's mount, a
  // saturation shell: drop_bad_returns; counted in the scan_received event). Returns once the
  // scan is on disk; throws SessionStoreError when it cannot be, UnusableScanError when no
  // point is left.
  StoredScan submit(const std::string& robot, const Pose& estimated, std::int64_t stamp_ns,
                    PointCloud cloud);
  // Scans stored but not yet in the live map.
  std::size_t pending() const;

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
  std::thread worker_;
};

}  // namespace scanplan::server
