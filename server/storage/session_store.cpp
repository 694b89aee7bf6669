#include "storage/session_store.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <set>

#include "common/iso_time.hpp"
#include "scanplan/io/ply_io.hpp"

namespace scanplan {
namespace {

std::string utc_now() {
  return iso8601_utc_now(TimePrecision::kMilliseconds);
}

// Writes `bytes` to `path` so that after return the file is whole on disk under its name:
// temporary file, fsync, rename, fsync of the directory.
void write_durably(const std::filesystem::path& path, const std::string& bytes) {
  const std::filesystem::path part = path.string() + ".part";
  const int fd = ::open(part.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw SessionStoreError("cannot create " + part.string() + ": " + std::strerror(errno));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      ::unlink(part.c_str());  // a full disk keeps no half file
      throw SessionStoreError("cannot write " + part.string() + ": " + why);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(part.c_str());
    throw SessionStoreError("cannot sync " + part.string() + ": " + why);
  }
  std::filesystem::rename(part, path);
  const int dir = ::open(path.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) {
      throw SessionStoreError(std::string("session database: ") + sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement& bind(int i, double v) { return check(sqlite3_bind_double(stmt_, i, v)); }
  Statement& bind(int i, std::int64_t v) { return check(sqlite3_bind_int64(stmt_, i, v)); }
  Statement& bind(int i, const std::string& v) {
    return check(
        sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
  }
  // For the next row of a statement run once per row.
  void reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw SessionStoreError(std::string("session database: ") + sqlite3_errmsg(db_));
  }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }
  bool null(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  std::string text(int col) const {
    const auto* t = sqlite3_column_text(stmt_, col);
    return t ? reinterpret_cast<const char*>(t) : "";
  }

 private:
  Statement& check(int rc) {
    if (rc != SQLITE_OK)
      throw SessionStoreError(std::string("session database: ") + sqlite3_errmsg(db_));
    return *this;
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

constexpr const char* kScanColumns =
    "id, robot, est_x, est_y, est_z, est_roll, est_pitch, est_yaw, x, y, z, roll, pitch, yaw, "
    "stamp_ns, points, file, received_at";
// A scan with its match, if it has one: scan_from_row reads these columns.
// With its latest exclusion record, which says whether it is out of the map now.
const std::string kScanSelect =
    std::string("SELECT ") + kScanColumns +
    ", applied, converged, method, matches.reason, time_ms, inlier_ratio, "
    "ex.excluded, ex.actor, ex.reason, ex.at, matches.information, goal_x, goal_y, goal_z, "
    "goal_drive_m, matches.weakest_constraint "
    "FROM "
    "scans "
    "LEFT JOIN matches "
    "ON matches.scan_id = scans.id LEFT JOIN (SELECT scan_id, excluded, actor, reason, at FROM "
    "exclusions WHERE id IN (SELECT MAX(id) FROM exclusions GROUP BY scan_id)) ex "
    "ON ex.scan_id = scans.id";

// A match's 4×4 information as stored: 16 numbers, row-major, separated by spaces (round-trip
// precision). Anything else reads as zero: the match then ties its scan in only weakly.
std::string information_text(const Eigen::Matrix4d& m) {
  std::string out;
  char number[32];
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      std::snprintf(number, sizeof number, "%.17g", m(r, c));
      if (!out.empty()) out += ' ';
      out += number;
    }
  }
  return out;
}

Eigen::Matrix4d information_from_text(const std::string& text) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  const char* at = text.c_str();
  for (int k = 0; k < 16; ++k) {
    char* end = nullptr;
    const double v = std::strtod(at, &end);
    if (end == at || !std::isfinite(v)) return Eigen::Matrix4d::Zero();
    m(k / 4, k % 4) = v;
    at = end;
  }
  return m;
}

StoredScan scan_from_row(const Statement& s) {
  StoredScan r;
  r.id = s.integer(0);
  r.robot = s.text(1);
  r.estimated = {s.real(2), s.real(3), s.real(4), s.real(5), s.real(6), s.real(7)};
  r.placed = {s.real(8), s.real(9), s.real(10), s.real(11), s.real(12), s.real(13)};
  r.stamp_ns = s.integer(14);
  r.points = static_cast<std::size_t>(s.integer(15));
  r.file = s.text(16);
  r.received_at = s.text(17);
  if (!s.null(18)) {
    r.match = StoredMatch{s.integer(18) != 0, s.integer(19) != 0, s.text(20),
                          s.text(21),         s.real(22),         s.real(23)};
  }
  if (!s.null(24) && s.integer(24) != 0) r.excluded = Exclusion{s.text(25), s.text(26), s.text(27)};
  if (r.match && !s.null(28)) r.match->information = information_from_text(s.text(28));
  if (!s.null(29) && !s.null(30) && !s.null(31))
    r.goal = Eigen::Vector3d(s.real(29), s.real(30), s.real(31));
  if (r.goal && !s.null(32)) r.goal_drive_m = s.real(32);
  if (r.match && !s.null(33)) r.match->weakest_constraint = s.real(33);
  return r;
}

}  // namespace

namespace {

std::filesystem::path created(std::filesystem::path dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir / "scans", ec);
  if (ec)
    throw SessionStoreError("cannot create the session directory " + dir.string() + ": " +
                            ec.message());
  return dir;
}

// The scan files under scans/ (not the set-aside ones below it, not unfinished writes).
std::vector<std::filesystem::path> scan_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "scans")) {
    if (entry.is_regular_file() && entry.path().extension() == ".ply") out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

SessionStore::DirectoryLock::DirectoryLock(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "session.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw SessionStoreError("cannot open " + path.string() + ": " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    std::string holder;
    std::getline(std::ifstream(path), holder);
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK) {
      throw SessionStoreError("the session " + dir.string() + " is open in another process" +
                              (holder.empty() ? std::string() : " (pid " + holder + ")") +
                              "; two servers on one session would write over each other's "
                              "scans: stop that one or give this one another --session");
    }
    throw SessionStoreError("cannot lock " + path.string() + ": " + std::strerror(err));
  }
  // Who holds it, for the message above; the lock, not the text, is what counts.
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t n = ::pwrite(fd_, pid.data(), pid.size(), 0);
  }
}

SessionStore::DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

SessionStore::SessionStore(std::filesystem::path dir) : dir_(created(std::move(dir))), lock_(dir_) {
  const std::string db_path = (dir_ / "session.sqlite").string();
  const bool had_database = std::filesystem::exists(db_path);
  if (sqlite3_open_v2(db_path.c_str(), &db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw SessionStoreError("cannot open " + db_path + ": " + why);
  }
  sqlite3_busy_timeout(db_, 5000);
  // WAL with full sync: a commit is on disk when it returns, and readers never block the writer.
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=FULL");
  exec(
      "CREATE TABLE IF NOT EXISTS scans(id INTEGER PRIMARY KEY, robot TEXT NOT NULL, "
      "est_x REAL, est_y REAL, est_z REAL, est_roll REAL, est_pitch REAL, est_yaw REAL, "
      "x REAL, y REAL, z REAL, roll REAL, pitch REAL, yaw REAL, stamp_ns INTEGER, "
      "points INTEGER, file TEXT NOT NULL, received_at TEXT NOT NULL)");
  exec(
      "CREATE TABLE IF NOT EXISTS matches(scan_id INTEGER PRIMARY KEY REFERENCES scans(id), "
      "applied INTEGER NOT NULL, converged INTEGER NOT NULL, method TEXT NOT NULL, "
      "reason TEXT NOT NULL, time_ms REAL NOT NULL, inlier_ratio REAL NOT NULL)");
  exec(
      "CREATE TABLE IF NOT EXISTS events(id INTEGER PRIMARY KEY, at TEXT NOT NULL, "
      "kind TEXT NOT NULL, json TEXT NOT NULL)");
  // Deleted annotations keep their rows (deleted_at, deleted_by set): what was marked on the map
  // and withdrawn is part of a rescue's record, and ids are never reused.
  exec(
      "CREATE TABLE IF NOT EXISTS annotations(id INTEGER PRIMARY KEY, kind TEXT NOT NULL, "
      "x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL, text TEXT NOT NULL, "
      "author TEXT NOT NULL, created_ns INTEGER NOT NULL, created_at TEXT NOT NULL, "
      "deleted_at TEXT, deleted_by TEXT)");
  // Sessions recorded before the pose graph have no information column.
  if (!has_column("matches", "information"))
    exec("ALTER TABLE matches ADD COLUMN information TEXT");
  // Nor how firmly the match fixed the pose.
  if (!has_column("matches", "weakest_constraint"))
    exec("ALTER TABLE matches ADD COLUMN weakest_constraint REAL");
  // Nor where the robot was sent for each scan (NULL: it was not, or not known).
  for (const char* column : {"goal_x", "goal_y", "goal_z", "goal_drive_m"}) {
    if (!has_column("scans", column))
      exec((std::string("ALTER TABLE scans ADD COLUMN ") + column + " REAL").c_str());
  }
  // Every pose the graph gave a scan, by revision: the session's history of corrections.
  exec(
      "CREATE TABLE IF NOT EXISTS pose_revisions(revision INTEGER NOT NULL, scan_id INTEGER NOT "
      "NULL REFERENCES scans(id), x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL, roll REAL "
      "NOT NULL, pitch REAL NOT NULL, yaw REAL NOT NULL, in_map INTEGER NOT NULL, at TEXT NOT "
      "NULL, PRIMARY KEY(revision, scan_id))");
  // Every change of the mission's parameters, in order: the latest row is in force.
  exec(
      "CREATE TABLE IF NOT EXISTS params(id INTEGER PRIMARY KEY, json TEXT NOT NULL, actor TEXT "
      "NOT NULL, at TEXT NOT NULL)");
  // Every exclusion and restoration, in order: the latest row per scan is its state.
  exec(
      "CREATE TABLE IF NOT EXISTS exclusions(id INTEGER PRIMARY KEY, scan_id INTEGER NOT NULL "
      "REFERENCES scans(id), excluded INTEGER NOT NULL, actor TEXT NOT NULL, reason TEXT NOT NULL, "
      "at TEXT NOT NULL)");
  if (!had_database) {
    if (const auto files = scan_files(dir_); !files.empty()) {
      sqlite3_close(db_);
      db_ = nullptr;
      for (const char* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(db_path + suffix);
      throw SessionStoreError(
          "the session " + dir_.string() + " holds " + std::to_string(files.size()) +
          " scan files (" + files.front().filename().string() +
          " ...) but no session.sqlite: opening it would start an empty session over them. "
          "Restore session.sqlite from a backup, or move the scans folder away to start anew");
    }
  }
  tidy_scan_files();
}

SessionStore::~SessionStore() {
  sqlite3_close(db_);
}

void SessionStore::rollback() const {
  // SQLite may have rolled the transaction back itself (a full disk: SQLITE_FULL); a second
  // rollback would then fail and hide the error that matters.
  if (sqlite3_get_autocommit(db_) == 0) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
}

bool SessionStore::has_column(const char* table, const char* column) const {
  Statement s(db_, (std::string("PRAGMA table_info(") + table + ")").c_str());
  while (s.step()) {
    if (s.text(1) == column) return true;
  }
  return false;
}

void SessionStore::exec(const char* sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string why = err ? err : "unknown error";
    sqlite3_free(err);
    throw SessionStoreError("session database (" + dir_.string() + "): " + why);
  }
}

void SessionStore::tidy_scan_files() const {
  std::set<std::string> known;
  Statement s(db_, "SELECT file FROM scans");
  while (s.step()) known.insert(s.text(0));
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "scans")) {
    if (!entry.is_regular_file()) continue;
    const std::filesystem::path& path = entry.path();
    // A .part is a write that never finished, never acknowledged.
    if (path.extension() == ".part") {
      std::filesystem::remove(path);
      continue;
    }
    if (known.count("scans/" + path.filename().string())) continue;
    // Whole, but its row never committed (a crash between the two), or a file someone put
    // here: kept for whoever wants it, out of the way of the ids to come.
    const std::filesystem::path aside = dir_ / "scans" / "unindexed";
    std::error_code ec;
    std::filesystem::create_directories(aside, ec);
    std::filesystem::path to = aside / path.filename();
    for (int n = 1; std::filesystem::exists(to); ++n) {
      to = aside / (path.filename().string() + "." + std::to_string(n));
    }
    std::filesystem::rename(path, to, ec);
    if (ec) {
      throw SessionStoreError("cannot move " + path.string() + " out of the way: " + ec.message());
    }
  }
}

StoredScan SessionStore::add_scan(const std::string& robot, const Pose& estimated,
                                  const Pose& placed, std::int64_t stamp_ns,
                                  const PointCloud& cloud,
                                  const std::optional<Eigen::Vector3d>& goal, double goal_drive_m) {
  std::lock_guard lock(mutex_);
  exec("BEGIN IMMEDIATE");
  try {
    StoredScan r;
    {
      Statement next(db_, "SELECT COALESCE(MAX(id), 0) + 1 FROM scans");
      next.step();
      r.id = next.integer(0);
    }
    char name[48];
    std::snprintf(name, sizeof name, "scans/scan_%06lld.ply", static_cast<long long>(r.id));
    r.robot = robot;
    r.estimated = estimated;
    r.placed = placed;
    r.stamp_ns = stamp_ns;
    r.points = cloud.size();
    r.file = name;
    r.received_at = utc_now();
    r.goal = goal;
    r.goal_drive_m = goal ? goal_drive_m : 0;
    write_durably(dir_ / r.file, write_ply_bytes(cloud, {"scanplan robot " + robot}));
    Statement ins(db_, (std::string("INSERT INTO scans(") + kScanColumns +
                        ", goal_x, goal_y, goal_z, goal_drive_m) "
                        "VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)")
                           .c_str());
    const Pose& e = estimated;
    const Pose& p = placed;
    ins.bind(1, r.id).bind(2, robot);
    ins.bind(3, e.x).bind(4, e.y).bind(5, e.z).bind(6, e.roll).bind(7, e.pitch).bind(8, e.yaw);
    ins.bind(9, p.x).bind(10, p.y).bind(11, p.z).bind(12, p.roll).bind(13, p.pitch).bind(14, p.yaw);
    ins.bind(15, stamp_ns).bind(16, static_cast<std::int64_t>(r.points)).bind(17, r.file);
    ins.bind(18, r.received_at);
    if (goal) {
      ins.bind(19, goal->x()).bind(20, goal->y()).bind(21, goal->z()).bind(22, r.goal_drive_m);
    }
    ins.step();
    exec("COMMIT");
    return r;
  } catch (...) {
    rollback();
    throw;
  }
}

void SessionStore::record_match(std::int64_t id, const StoredMatch& m, const Pose& p) {
  std::lock_guard lock(mutex_);
  exec("BEGIN IMMEDIATE");
  try {
    Statement ins(db_,
                  "INSERT OR REPLACE INTO matches(scan_id, applied, converged, method, reason, "
                  "time_ms, inlier_ratio, information, weakest_constraint) "
                  "VALUES(?,?,?,?,?,?,?,?,?)");
    ins.bind(1, id).bind(2, std::int64_t{m.applied}).bind(3, std::int64_t{m.converged});
    ins.bind(4, m.method).bind(5, m.reason).bind(6, m.time_ms).bind(7, m.inlier_ratio);
    ins.bind(8, information_text(m.information)).bind(9, m.weakest_constraint);
    ins.step();
    Statement s(db_,
                "UPDATE scans SET x = ?, y = ?, z = ?, roll = ?, pitch = ?, yaw = ? WHERE id = ?");
    s.bind(1, p.x).bind(2, p.y).bind(3, p.z).bind(4, p.roll).bind(5, p.pitch).bind(6, p.yaw);
    s.bind(7, id);
    s.step();
    exec("COMMIT");
  } catch (...) {
    rollback();
    throw;
  }
}

std::int64_t SessionStore::record_pose_revision(const std::vector<RevisedPose>& poses) {
  std::lock_guard lock(mutex_);
  exec("BEGIN IMMEDIATE");
  try {
    std::int64_t revision = 0;
    {
      Statement next(db_, "SELECT COALESCE(MAX(revision), 0) + 1 FROM pose_revisions");
      next.step();
      revision = next.integer(0);
    }
    const std::string at = utc_now();
    Statement ins(db_,
                  "INSERT INTO pose_revisions(revision, scan_id, x, y, z, roll, pitch, yaw, "
                  "in_map, at) VALUES(?,?,?,?,?,?,?,?,?,?)");
    for (const RevisedPose& r : poses) {
      const Pose& p = r.pose;
      ins.reset();
      ins.bind(1, revision).bind(2, r.scan).bind(3, p.x).bind(4, p.y).bind(5, p.z);
      ins.bind(6, p.roll).bind(7, p.pitch).bind(8, p.yaw).bind(9, std::int64_t{r.in_map});
      ins.bind(10, at);
      ins.step();
    }
    exec("COMMIT");
    return revision;
  } catch (...) {
    rollback();
    throw;
  }
}

std::vector<RevisedPose> SessionStore::latest_poses() const {
  std::lock_guard lock(mutex_);
  std::vector<RevisedPose> out;
  Statement s(db_,
              "SELECT scan_id, x, y, z, roll, pitch, yaw, in_map FROM pose_revisions WHERE "
              "(scan_id, revision) IN (SELECT scan_id, MAX(revision) FROM pose_revisions GROUP "
              "BY scan_id) ORDER BY scan_id");
  while (s.step()) {
    out.push_back({s.integer(0),
                   {s.real(1), s.real(2), s.real(3), s.real(4), s.real(5), s.real(6)},
                   s.integer(7) != 0});
  }
  return out;
}

std::int64_t SessionStore::pose_revision() const {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT COALESCE(MAX(revision), 0) FROM pose_revisions");
  s.step();
  return s.integer(0);
}

std::optional<StoredScan> SessionStore::set_excluded(std::int64_t id, bool excluded,
                                                     const std::string& by,
                                                     const std::string& reason) {
  std::lock_guard lock(mutex_);
  exec("BEGIN IMMEDIATE");
  try {
    {
      Statement known(db_, "SELECT COUNT(*) FROM scans WHERE id = ?");
      known.bind(1, id);
      known.step();
      if (known.integer(0) == 0) {
        rollback();
        return std::nullopt;
      }
    }
    Statement ins(db_,
                  "INSERT INTO exclusions(scan_id, excluded, actor, reason, at) VALUES(?,?,?,?,?)");
    ins.bind(1, id).bind(2, std::int64_t{excluded}).bind(3, by).bind(4, reason).bind(5, utc_now());
    ins.step();
    Statement s(db_, (kScanSelect + " WHERE scans.id = ?").c_str());
    s.bind(1, id);
    s.step();
    StoredScan out = scan_from_row(s);
    exec("COMMIT");
    return out;
  } catch (...) {
    rollback();
    throw;
  }
}

std::vector<StoredScan> SessionStore::scans() const {
  std::lock_guard lock(mutex_);
  std::vector<StoredScan> out;
  Statement s(db_, (kScanSelect + " ORDER BY id").c_str());
  while (s.step()) out.push_back(scan_from_row(s));
  return out;
}

std::vector<SessionEvent> SessionStore::events(std::size_t limit) const {
  std::lock_guard lock(mutex_);
  std::vector<SessionEvent> out;
  Statement s(db_,
              "SELECT id, at, kind, json FROM (SELECT id, at, kind, json FROM events "
              "ORDER BY id DESC LIMIT ?) ORDER BY id");
  s.bind(1, static_cast<std::int64_t>(limit));
  while (s.step()) out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3)});
  return out;
}

std::optional<StoredScan> SessionStore::scan(std::int64_t id) const {
  std::lock_guard lock(mutex_);
  Statement s(db_, (kScanSelect + " WHERE id = ?").c_str());
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return scan_from_row(s);
}

PointCloud SessionStore::load_points(const StoredScan& scan) const {
  return read_ply(dir_ / scan.file);
}

std::int64_t SessionStore::append_event(const std::string& kind, const std::string& json) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "INSERT INTO events(at, kind, json) VALUES(?, ?, ?)");
  s.bind(1, utc_now()).bind(2, kind).bind(3, json);
  s.step();
  return sqlite3_last_insert_rowid(db_);
}

void SessionStore::record_params(const std::string& json, const std::string& by) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "INSERT INTO params(json, actor, at) VALUES(?, ?, ?)");
  s.bind(1, json).bind(2, by).bind(3, utc_now());
  s.step();
}

std::optional<std::string> SessionStore::latest_params() const {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT json FROM params ORDER BY id DESC LIMIT 1");
  if (!s.step()) return std::nullopt;
  return s.text(0);
}

Annotation SessionStore::add_annotation(const std::string& kind, double x, double y, double z,
                                        const std::string& text, const std::string& author) {
  if (std::find(kAnnotationKinds.begin(), kAnnotationKinds.end(), kind) == kAnnotationKinds.end()) {
    throw SessionStoreError("unknown annotation kind '" + kind +
                            "': it is victim, hazard, blocked or note");
  }
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    throw SessionStoreError("an annotation's coordinates must be finite numbers");
  }
  if (text.size() > kMaxAnnotationTextBytes || author.size() > kMaxAnnotationAuthorBytes) {
    throw SessionStoreError("an annotation's text is limited to " +
                            std::to_string(kMaxAnnotationTextBytes) + " bytes and its author to " +
                            std::to_string(kMaxAnnotationAuthorBytes));
  }
  const auto now = std::chrono::system_clock::now();
  Annotation a;
  a.kind = kind;
  a.x = x;
  a.y = y;
  a.z = z;
  a.text = text;
  a.author = author;
  a.created_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
  a.created_at = iso8601_utc(now, TimePrecision::kMilliseconds);
  std::lock_guard lock(mutex_);
  // One statement in autocommit mode: with WAL and synchronous=FULL it is durable on return.
  Statement s(db_,
              "INSERT INTO annotations(kind, x, y, z, text, author, created_ns, created_at) "
              "VALUES(?, ?, ?, ?, ?, ?, ?, ?)");
  s.bind(1, kind).bind(2, x).bind(3, y).bind(4, z).bind(5, text).bind(6, author);
  s.bind(7, a.created_ns).bind(8, a.created_at);
  s.step();
  a.id = sqlite3_last_insert_rowid(db_);
  return a;
}

bool SessionStore::delete_annotation(std::int64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "UPDATE annotations SET deleted_at = ?, deleted_by = ? "
              "WHERE id = ? AND deleted_at IS NULL");
  s.bind(1, utc_now()).bind(2, by).bind(3, id);
  s.step();
  return sqlite3_changes(db_) > 0;
}

std::vector<Annotation> SessionStore::annotations() const {
  std::lock_guard lock(mutex_);
  std::vector<Annotation> out;
  Statement s(db_,
              "SELECT id, kind, x, y, z, text, author, created_ns, created_at FROM annotations "
              "WHERE deleted_at IS NULL ORDER BY id");
  while (s.step()) {
    Annotation a;
    a.id = s.integer(0);
    a.kind = s.text(1);
    a.x = s.real(2);
    a.y = s.real(3);
    a.z = s.real(4);
    a.text = s.text(5);
    a.author = s.text(6);
    a.created_ns = s.integer(7);
    a.created_at = s.text(8);
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace scanplan
