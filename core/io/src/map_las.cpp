// LAS 1.4 as ASPRS specifies it (R15, 2019): the public header block, no variable length
// records, point data record format 7.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "map_points.hpp"
#include "scanplan/io/map_export.hpp"

namespace scanplan {
namespace {

constexpr std::uint16_t kHeaderSize = 375;
constexpr std::uint8_t kPointFormat = 7;
constexpr std::uint16_t kPointRecordLength = 36;
// Millimetres: the map's accuracy is a centimetre, and ±2^31 mm reach ±2,000 km.
constexpr double kScale = 0.001;

class Writer {
 public:
  explicit Writer(std::string& out) : out_(out) {}
  template <typename T>
  void put(T value) {
    detail::append_le(out_, value);
  }
  // A fixed-width text field, padded with NULs (cut to fit).
  void text(const std::string& s, std::size_t width) {
    out_.append(s.substr(0, width));
    out_.append(width - std::min(width, s.size()), '\0');
  }
  void zeros(std::size_t n) { out_.append(n, '\0'); }

 private:
  std::string& out_;
};

}  // namespace

std::string map_las_bytes(const std::vector<MapPart>& parts, std::time_t created,
                          const std::string& software) {
  std::uint64_t count = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const MapPart& part : parts) {
    if (part.scan_id > std::numeric_limits<std::uint16_t>::max()) {
      throw std::invalid_argument("LAS keeps the scan id as a 16-bit point source id; scan " +
                                  std::to_string(part.scan_id) + " does not fit");
    }
    if (!part.points) continue;
    for (const Eigen::Vector3f& p : part.points->points) {
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
    }
    count += part.points->size();
  }
  if (count == 0) lo = hi = Eigen::Vector3d::Zero();
  // The offset is the minimum corner in whole metres: every coordinate is then a small
  // positive integer of millimetres.
  const Eigen::Vector3d offset = lo.array().floor();

  std::tm day{};
  gmtime_r(&created, &day);
  std::string out;
  out.reserve(kHeaderSize + count * kPointRecordLength);
  Writer w(out);
  w.text("LASF", 4);
  w.put<std::uint16_t>(0);       // file source id
  w.put<std::uint16_t>(1 << 4);  // global encoding: a CRS, if any, would be WKT (formats 6-10)
  w.zeros(16);                   // project GUID
  w.put<std::uint8_t>(1);        // version 1.4
  w.put<std::uint8_t>(4);
  w.text("scanplan map frame (local, metres)", 32);  // system identifier
  w.text(software, 32);
  w.put<std::uint16_t>(static_cast<std::uint16_t>(day.tm_yday + 1));
  w.put<std::uint16_t>(static_cast<std::uint16_t>(day.tm_year + 1900));
  w.put<std::uint16_t>(kHeaderSize);
  w.put<std::uint32_t>(kHeaderSize);  // offset to point data: no VLRs
  w.put<std::uint32_t>(0);            // number of VLRs
  w.put<std::uint8_t>(kPointFormat);
  w.put<std::uint16_t>(kPointRecordLength);
  w.put<std::uint32_t>(0);  // legacy point count: zero for formats 6-10
  w.zeros(5 * 4);           // legacy points by return
  for (int i = 0; i < 3; ++i) w.put<double>(kScale);
  for (int i = 0; i < 3; ++i) w.put<double>(offset[i]);
  for (int i = 0; i < 3; ++i) {
    w.put<double>(hi[i]);
    w.put<double>(lo[i]);
  }
  w.put<std::uint64_t>(0);  // start of waveform data
  w.put<std::uint64_t>(0);  // start of the first EVLR
  w.put<std::uint32_t>(0);  // number of EVLRs
  w.put<std::uint64_t>(count);
  w.put<std::uint64_t>(count);  // every point is the first (and only) return
  w.zeros(14 * 8);

  const auto scaled = [&](float v, int axis) {
    return static_cast<std::int32_t>(std::llround((v - offset[axis]) / kScale));
  };
  detail::for_each_map_point(parts, [&](const Eigen::Vector3f& p, const Rgb& c, std::uint32_t id) {
    w.put<std::int32_t>(scaled(p.x(), 0));
    w.put<std::int32_t>(scaled(p.y(), 1));
    w.put<std::int32_t>(scaled(p.z(), 2));
    w.put<std::uint16_t>(0);    // intensity: not measured
    w.put<std::uint8_t>(0x11);  // return 1 of 1
    w.put<std::uint8_t>(0);     // classification flags, channel, scan direction, edge
    w.put<std::uint8_t>(0);     // classification: never classified
    w.put<std::uint8_t>(0);     // user data
    w.put<std::int16_t>(0);     // scan angle
    w.put<std::uint16_t>(static_cast<std::uint16_t>(id));  // point source id
    w.put<double>(0);                                      // GPS time: not recorded
    for (const std::uint8_t v : c) w.put<std::uint16_t>(static_cast<std::uint16_t>(v * 257));
  });
  return out;
}

}  // namespace scanplan
