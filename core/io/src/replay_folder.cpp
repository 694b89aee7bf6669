#include "scanplan/io/replay_folder.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "scanplan/io/scan_file.hpp"
#include "scanplan/io/threedtk.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(
        trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

bool parse_double(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size() && std::isfinite(out);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

enum Column { kFile, kX, kY, kZ, kYaw, kRoll, kPitch, kColumnCount };
constexpr std::array<std::string_view, kColumnCount> kColumnNames{
    "file", "x", "y", "z", "yaw_deg", "roll_deg", "pitch_deg"};

// The number in "scan<digits>.3d", or -1 for any other name.
long threedtk_scan_number(const std::string& name) {
  constexpr std::string_view kPrefix = "scan", kSuffix = ".3d";
  if (name.size() <= kPrefix.size() + kSuffix.size() || !name.starts_with(kPrefix) ||
      !name.ends_with(kSuffix)) {
    return -1;
  }
  const std::string_view digits =
      std::string_view(name).substr(kPrefix.size(), name.size() - kPrefix.size() - kSuffix.size());
  if (digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return -1;
  }
  return std::stol(std::string(digits));
}

}  // namespace

ReplayFolder::ReplayFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  const auto status = fs::status(dir_, ec);
  if (!fs::exists(status)) throw ReplayFolderError(dir_.string() + ": no such directory");
  if (!fs::is_directory(status)) throw ReplayFolderError(dir_.string() + ": not a directory");
  const fs::path csv = dir_ / "poses.csv";
  if (fs::exists(csv, ec)) {
    list_csv(csv);
  } else {
    list_threedtk();
  }
}

namespace {

using ColumnIndex = std::array<int, kColumnCount>;  // cell index of each column, -1 when absent
using LineFailure = std::function<void(const std::string& what)>;

ColumnIndex header_columns(const std::vector<std::string_view>& cells, const LineFailure& fail) {
  ColumnIndex index;
  index.fill(-1);
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const auto it = std::find(kColumnNames.begin(), kColumnNames.end(), cells[c]);
    if (it == kColumnNames.end()) {
      fail("unknown column '" + std::string(cells[c]) +
           "' (the columns are file,x,y,z,yaw_deg and optionally roll_deg,pitch_deg)");
    }
    const auto col = static_cast<std::size_t>(it - kColumnNames.begin());
    if (index[col] >= 0) fail("column '" + std::string(cells[c]) + "' appears twice");
    index[col] = static_cast<int>(c);
  }
  for (std::size_t col = kFile; col <= kYaw; ++col) {
    if (index[col] < 0) {
      fail("the header has no '" + std::string(kColumnNames[col]) +
           "' column (it needs file,x,y,z,yaw_deg)");
    }
  }
  return index;
}

// One scan's row: its file (which must exist in `dir`) and pose.
ReplayFolder::Entry entry_of(const std::vector<std::string_view>& cells, const ColumnIndex& index,
                             const fs::path& dir, const LineFailure& fail) {
  std::array<double, kColumnCount> v{};
  for (std::size_t col = kX; col < kColumnCount; ++col) {
    if (index[col] < 0) continue;
    const std::string_view cell = cells[static_cast<std::size_t>(index[col])];
    if (!parse_double(cell, v[col])) {
      fail("column '" + std::string(kColumnNames[col]) + "': '" + std::string(cell.substr(0, 40)) +
           "' is not a finite number");
    }
  }
  const std::string_view name = cells[static_cast<std::size_t>(index[kFile])];
  if (name.empty()) fail("the 'file' column is empty");
  const fs::path rel(name);
  const std::string ext = lower(rel.extension().string());
  if (ext != ".ply" && ext != ".pcd")
    fail("scan file '" + std::string(name) + "' is not .ply or .pcd");
  ReplayFolder::Entry e;
  e.scan = rel.is_absolute() ? rel : dir / rel;
  std::error_code ec;
  if (!fs::is_regular_file(e.scan, ec)) {
    fail("scan file '" + std::string(name) + "' does not exist in " + dir.string());
  }
  e.pose.x = v[kX];
  e.pose.y = v[kY];
  e.pose.z = v[kZ];
  e.pose.yaw = deg2rad(v[kYaw]);
  e.pose.roll = deg2rad(v[kRoll]);
  e.pose.pitch = deg2rad(v[kPitch]);
  return e;
}

}  // namespace

void ReplayFolder::list_csv(const fs::path& csv) {
  std::string text;
  try {
    text = read_scan_file_bytes(csv);
  } catch (const ScanFileError& e) {
    throw ReplayFolderError(e.what());
  }
  // Spreadsheets save CSV with a byte-order mark; it is not part of the first column's name.
  std::string_view rest = text;
  if (rest.starts_with("\xEF\xBB\xBF")) rest.remove_prefix(3);

  std::optional<ColumnIndex> index;
  std::size_t columns = 0;
  std::size_t line_no = 0;
  const LineFailure fail = [&](const std::string& what) {
    throw ReplayFolderError(csv.string() + " line " + std::to_string(line_no) + ": " + what);
  };
  while (!rest.empty()) {
    const std::size_t nl = rest.find('\n');
    const std::string_view line = trim(rest.substr(0, nl));
    rest.remove_prefix(nl == std::string_view::npos ? rest.size() : nl + 1);
    ++line_no;
    if (line.empty()) continue;
    const auto cells = split_commas(line);
    if (!index) {
      columns = cells.size();
      index = header_columns(cells, fail);
      continue;
    }
    if (cells.size() != columns) {
      fail(std::to_string(cells.size()) + " values but the header has " + std::to_string(columns) +
           " columns");
    }
    Entry e = entry_of(cells, *index, dir_, fail);
    e.image = image_beside(e.scan);
    entries_.push_back(std::move(e));
  }
  if (!index) throw ReplayFolderError(csv.string() + ": is empty (it needs a header line)");
  if (entries_.empty()) throw ReplayFolderError(csv.string() + ": lists no scans");
}

void ReplayFolder::list_threedtk() {
  std::map<long, fs::path> scans;
  std::error_code ec;
  for (const auto& de : fs::directory_iterator(dir_, ec)) {
    if (!de.is_regular_file(ec)) continue;
    const std::string name = de.path().filename().string();
    const long number = threedtk_scan_number(name);
    if (number < 0) continue;
    const auto [it, inserted] = scans.emplace(number, de.path());
    if (!inserted) {
      throw ReplayFolderError(dir_.string() + ": " + it->second.filename().string() + " and " +
                              name + " have the same scan number");
    }
  }
  if (ec) throw ReplayFolderError(dir_.string() + ": cannot list: " + ec.message());
  if (scans.empty()) {
    throw ReplayFolderError(dir_.string() +
                            ": neither poses.csv nor 3DTK scanNNN.3d files (a replay folder "
                            "needs one or the other)");
  }
  for (const auto& [number, scan] : scans) {
    fs::path pose_file = scan;
    pose_file.replace_extension(".pose");
    if (!fs::is_regular_file(pose_file, ec)) {
      throw ReplayFolderError(pose_file.string() + ": missing (each scanNNN.3d needs a .pose)");
    }
    Entry e;
    e.scan = scan;
    try {
      e.pose = Pose::from_isometry(read_threedtk_pose(pose_file));
    } catch (const ScanFileError& err) {
      throw ReplayFolderError(err.what());
    }
    e.image = image_beside(scan);
    entries_.push_back(std::move(e));
  }
}

std::optional<fs::path> ReplayFolder::image_beside(const fs::path& scan) const {
  fs::path image = scan;
  image.replace_extension(".jpg");
  std::error_code ec;
  if (fs::is_regular_file(image, ec)) return image;
  return std::nullopt;
}

const ReplayFolder::Entry& ReplayFolder::entry(std::size_t i) const {
  if (i >= entries_.size()) {
    throw std::out_of_range("replay folder " + dir_.string() + " has " +
                            std::to_string(entries_.size()) + " scans; there is no scan " +
                            std::to_string(i));
  }
  return entries_[i];
}

PointCloud ReplayFolder::load(std::size_t i) const {
  return read_point_cloud(entry(i).scan);
}

}  // namespace scanplan
