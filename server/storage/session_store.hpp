#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"

struct sqlite3;

namespace scanplan {

class SessionStoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// How matching placed a scan (paper §4; MapMatch): recorded once the match ran.
struct StoredMatch {
  bool applied = false;    // the scan sits where the match put it
  bool converged = false;  // the match settled and passed the sanity check
  std::string method;      // "search-gicp", "ndt-icp", ...
  std::string reason;      // why it was not applied (empty when it was)
  double time_ms = 0;
  double inlier_ratio = 0;
  // How firmly the match fixes x, y, z and yaw (MapMatch::information, map frame): the pose
  // graph weighs the match by it when the session is brought back. Zero in sessions recorded
  // before the graph (such a match ties its scan in only weakly).
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  // AlignmentQuality::weakest_constraint of the result: how firmly the matched surfaces fix the
  // pose in its least fixed direction (a corridor is near 0). Zero in sessions recorded before
  // it was kept.
  double weakest_constraint = 0;
};

// A scan's pose as one revision of the pose graph left it (issue 17): in the map frame, and
// whether the scan was in the map or still waiting for a match that ties it in.
struct RevisedPose {
  std::int64_t scan = 0;
  Pose pose;
  bool in_map = true;
};

// The operator took the scan out of the map (DELETE /api/v1/scans/{id}): who, why, when. The
// scan and its file stay; putting it back is recorded the same way.
struct Exclusion {
  std::string by;
  std::string reason;
  std::string at;  // UTC, ISO 8601 with milliseconds
};

struct StoredScan {
  std::int64_t id = 0;
  std::string robot;
  Pose estimated;  // the pose the robot reported
  Pose placed;     // where the map put the scan (after matching)
  std::int64_t stamp_ns = 0;
  std::size_t points = 0;
  std::string file;                   // the scan's PLY, relative to the session directory
  std::string received_at;            // UTC, ISO 8601
  std::optional<StoredMatch> match;   // none for the first scan, with matching off, or not yet
  std::optional<Exclusion> excluded;  // set while the operator keeps it out of the map
  // Where the robot was sent for this scan (the approved candidate it reached, map frame): a
  // scan the map cannot place is claimed for the planner there (Placement::goal).
  std::optional<Eigen::Vector3d> goal;
  // The length of the path the planner gave the robot there (0: not known): odometry drifts
  // with the path driven (Placement::driven_m).
  double goal_drive_m = 0;
};

// One row of the session's record of what happened (append_event).
struct SessionEvent {
  std::int64_t id = 0;
  std::string at;  // UTC, ISO 8601 with milliseconds
  std::string kind;
  std::string json;
};

// A mark the operator put on the map (DESIGN.md "REST": annotations).
struct Annotation {
  std::int64_t id = 0;
  std::string kind;            // one of kAnnotationKinds
  double x = 0, y = 0, z = 0;  // map frame, metres
  std::string text;
  std::string author;           // who made it, as decisions record it ("operator", "operator Ann")
  std::int64_t created_ns = 0;  // since the epoch
  std::string created_at;       // the same instant, UTC, ISO 8601
};

inline constexpr std::array<std::string_view, 4> kAnnotationKinds = {"victim", "hazard", "blocked",
                                                                     "note"};
// Enough for a short report ("two adults, one trapped under the stairs, responsive"); a longer
// text is a document, not a mark on a map.
inline constexpr std::size_t kMaxAnnotationTextBytes = 1000;
inline constexpr std::size_t kMaxAnnotationAuthorBytes = 100;

// A session on disk (DESIGN.md "Session directory"): session.sqlite in WAL mode plus one binary
// PLY per scan under scans/. A scan is acknowledged only once both are durable: the PLY is
// written to a temporary name, synced and renamed before its row commits, so a process killed
// at any moment leaves either the whole scan or none of it (a PLY without its row is
// set aside under scans/unindexed/ on the next open, never deleted; an unfinished .part file is
// removed). Opening refuses (SessionStoreError) a session another process has open, and a
// folder whose scan files have no database beside them (opening it would start an empty
// session over them). Safe to use from several threads.
class SessionStore {
 public:
  // Opens or creates the session in `dir`; throws SessionStoreError naming the path.
  explicit SessionStore(std::filesystem::path dir);
  ~SessionStore();
  SessionStore(const SessionStore&) = delete;
  SessionStore& operator=(const SessionStore&) = delete;

  const std::filesystem::path& dir() const { return dir_; }

  // `cloud` in the scan's own frame; `goal` where the robot was sent for it, if it was, and
  // `goal_drive_m` the path there (StoredScan). Returns the new scan with its id.
  StoredScan add_scan(const std::string& robot, const Pose& estimated, const Pose& placed,
                      std::int64_t stamp_ns, const PointCloud& cloud,
                      const std::optional<Eigen::Vector3d>& goal = std::nullopt,
                      double goal_drive_m = 0);
  // Records how matching went for scan `id` and where the scan was placed (the match's
  // correction, or the reported pose carried into the map frame when it was refused): both in
  // one transaction.
  void record_match(std::int64_t id, const StoredMatch& match, const Pose& placed);
  // Takes scan `id` out of the map (`excluded`) or puts it back, recorded with who and why (the
  // full history is kept; scans() carries the latest). Returns the scan as it now stands;
  // nothing for an unknown id.
  // Records a revision of the scans' poses (the pose graph moved them): the scans named, at
  // their new poses, in one transaction. Returns the revision's number (1, 2, ...). Every
  // revision is kept.
  std::int64_t record_pose_revision(const std::vector<RevisedPose>& poses);
  // Each scan's pose in its latest revision, by scan id (scans never revised are missing).
  std::vector<RevisedPose> latest_poses() const;
  // The number of the latest revision; 0 before the first.
  std::int64_t pose_revision() const;
  std::optional<StoredScan> set_excluded(std::int64_t id, bool excluded, const std::string& by,
                                         const std::string& reason);
  std::vector<StoredScan> scans() const;
  // The newest `limit` events recorded with append_event, oldest first.
  std::vector<SessionEvent> events(std::size_t limit) const;
  std::optional<StoredScan> scan(std::int64_t id) const;
  PointCloud load_points(const StoredScan& scan) const;

  // A key-value record of what happened (decisions, events), in order, as JSON text.
  std::int64_t append_event(const std::string& kind, const std::string& json);

  // The mission's parameters as the operator last set them (PUT /api/v1/params: α, the policy,
  // the target region, the no-go zones), as JSON text, with who set them; every change is
  // kept. latest_params() is what a restarted server resumes with; nothing before the first.
  void record_params(const std::string& json, const std::string& by);
  std::optional<std::string> latest_params() const;

  // Stores a new annotation, committed (on disk) when this returns, and returns it with its id
  // and creation time. Ids are never reused, even after a deletion. Throws SessionStoreError for
  // an unknown kind, a non-finite coordinate or a text or author over the limits, so nothing
  // invalid is ever stored.
  Annotation add_annotation(const std::string& kind, double x, double y, double z,
                            const std::string& text, const std::string& author);
  // Marks annotation `id` deleted by `by` (the row stays, for the record); false when there is
  // no such annotation or it was already deleted.
  bool delete_annotation(std::int64_t id, const std::string& by);
  // The annotations not deleted, oldest first.
  std::vector<Annotation> annotations() const;

 private:
  void exec(const char* sql) const;
  bool has_column(const char* table, const char* column) const;
  // Ends a failed transaction, if SQLite has not already; never throws.
  void rollback() const;
  // Removes unfinished writes and sets aside PLYs without a row (see the class comment).
  void tidy_scan_files() const;

  // Held open, under an exclusive flock, for the store's life: a second server on the same
  // session is refused instead of writing scans over the first one's (issue 16).
  class DirectoryLock {
   public:
    explicit DirectoryLock(const std::filesystem::path& dir);
    ~DirectoryLock();
    DirectoryLock(const DirectoryLock&) = delete;
    DirectoryLock& operator=(const DirectoryLock&) = delete;

   private:
    int fd_ = -1;
  };

  std::filesystem::path dir_;
  DirectoryLock lock_;
  sqlite3* db_ = nullptr;
  // One connection, so one writer at a time: a transaction spans several calls.
  mutable std::mutex mutex_;
};

}  // namespace scanplan
