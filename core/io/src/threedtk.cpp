#include "scanplan/io/threedtk.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "text_scan.hpp"

namespace scanplan {
namespace {

using text_scan::fail;
using text_scan::fail_line;
using text_scan::parse_double;

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

// All numbers of a small file, ignoring line structure as 3DTK's `>>` reading does, but
// remembering each number's line for messages.
struct Numbers {
  std::vector<double> values;
  std::vector<std::size_t> lines;
};

Numbers numbers_of(std::string_view text, const std::string& source, std::size_t max_count) {
  Numbers n;
  std::size_t line = 1;
  for (std::size_t i = 0; i < text.size();) {
    if (is_space(text[i])) {
      if (text[i] == '\n') ++line;
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && !is_space(text[j])) ++j;
    const std::string_view tok = text.substr(i, j - i);
    if (n.values.size() == max_count) {
      fail_line(source, line,
                "unexpected '" + std::string(tok.substr(0, 40)) + "' after " +
                    std::to_string(max_count) + " numbers");
    }
    double v = 0;
    if (!parse_double(tok, v) || !std::isfinite(v)) {
      const std::string shown(tok.substr(0, 40));
      fail_line(source, line, "'" + shown + "' is not a finite number");
    }
    n.values.push_back(v);
    n.lines.push_back(line);
    i = j;
  }
  return n;
}

Eigen::Isometry3d to_ours(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_cm) {
  const Eigen::Matrix3d C = threedtk_to_ours_basis();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = C * R * C.transpose();
  T.translation() = C * t_cm / 100.0;
  return T;
}

}  // namespace

Eigen::Matrix3d threedtk_to_ours_basis() {
  Eigen::Matrix3d C;
  // Rows pick our x, y, z out of 3DTK's (x, y, z): ours = (z, -x, y).
  C << 0, 0, 1,  //
      -1, 0, 0,  //
      0, 1, 0;
  return C;
}

PointCloud parse_threedtk_scan(std::string_view text, const std::string& source_name,
                               ThreedtkScanInfo* info, const ThreedtkScanOptions& options) {
  ThreedtkScanInfo stats;
  PointCloud cloud;
  // One point per line at most, and a point line takes at least 6 bytes ("1 2 3\n"), so this
  // reservation stays in proportion to the file however many empty lines it has.
  const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  cloud.points.reserve(std::min(lines, text.size() / 6 + 1));
  const double min_range_cm = options.min_range_m * 100.0;
  const double max_range_cm = options.max_range_m * 100.0;

  text_scan::LineReader reader(text, source_name);
  std::string_view line;
  std::array<std::string_view, 4> tok;
  while (reader.next_line(line)) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < line.size();) {
      if (is_space(line[i])) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < line.size() && !is_space(line[j])) ++j;
      if (count < tok.size()) tok[count] = line.substr(i, j - i);
      ++count;
      i = j;
    }
    if (count == 0) continue;
    if (count != 3) {
      fail_line(source_name, reader.line_number(),
                "expected 3 numbers 'x y z' (cm), got " + std::to_string(count) + " values");
    }
    ++stats.lines;
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      if (!parse_double(tok[a], p[a])) {
        const std::string shown(tok[a].substr(0, 40));
        fail_line(source_name, reader.line_number(), "'" + shown + "' is not a number");
      }
    }
    if (!p.allFinite()) {
      ++stats.dropped_non_finite;
      continue;
    }
    const double range_cm = p.norm();
    if (range_cm < min_range_cm) {
      ++stats.dropped_short;
      continue;
    }
    if (range_cm > max_range_cm) {
      ++stats.dropped_far;
      continue;
    }
    // (x, y, z) -> (z, -x, y) / 100, written out rather than multiplied by C: this loop runs
    // for every point of every scan.
    const Eigen::Vector3f q(static_cast<float>(p.z() / 100.0), static_cast<float>(-p.x() / 100.0),
                            static_cast<float>(p.y() / 100.0));
    if (!q.allFinite()) {  // a finite double can still overflow a float
      ++stats.dropped_non_finite;
      continue;
    }
    cloud.points.push_back(q);
  }
  if (info) *info = stats;
  return cloud;
}

PointCloud read_threedtk_scan(const std::filesystem::path& file, ThreedtkScanInfo* info,
                              const ThreedtkScanOptions& options) {
  const std::string text = read_scan_file_bytes(file);
  return parse_threedtk_scan(text, file.string(), info, options);
}

Eigen::Isometry3d parse_threedtk_pose(std::string_view text, const std::string& source_name) {
  const Numbers n = numbers_of(text, source_name, 6);
  if (n.values.size() != 6) {
    fail(source_name, "expected 6 numbers (tx ty tz in cm, then rx ry rz in degrees), got " +
                          std::to_string(n.values.size()));
  }
  const Eigen::Vector3d t(n.values[0], n.values[1], n.values[2]);
  constexpr double kDeg = 0.017453292519943295;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(n.values[3] * kDeg, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(n.values[4] * kDeg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(n.values[5] * kDeg, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  return to_ours(R, t);
}

Eigen::Isometry3d read_threedtk_pose(const std::filesystem::path& file) {
  return parse_threedtk_pose(read_scan_file_bytes(file), file.string());
}

Eigen::Isometry3d parse_threedtk_reference(std::string_view text, const std::string& source_name) {
  const Numbers n = numbers_of(text, source_name, 17);
  if (n.values.size() != 16 && n.values.size() != 17) {
    fail(source_name,
         "expected 16 numbers (a column-major 4x4 matrix) and an optional colour index, got " +
             std::to_string(n.values.size()));
  }
  const Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix4d>(n.values.data());  // column-major
  constexpr double kTol = 1e-3;  // the files carry six significant digits
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > kTol) {
    fail(source_name, "the matrix's last row is not 0 0 0 1 (numbers 4, 8, 12, 16 of the file)");
  }
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > kTol ||
      R.determinant() < 0) {
    fail(source_name, "the matrix's upper-left 3x3 block is not a rotation");
  }
  return to_ours(R, M.topRightCorner<3, 1>());
}

Eigen::Isometry3d read_threedtk_reference(const std::filesystem::path& file) {
  return parse_threedtk_reference(read_scan_file_bytes(file), file.string());
}

}  // namespace scanplan
