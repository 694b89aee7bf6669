#include "app/exports.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "scanplan/geometry/pose.hpp"

namespace scanplan::server {
namespace {

// A CSV field: quoted (inner quotes doubled) when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

std::string poses_csv(const std::vector<StoredScan>& scans) {
  std::string out = "scan,robot,x,y,z,roll_deg,pitch_deg,yaw_deg,received_at\n";
  char numbers[160];
  for (const StoredScan& s : scans) {
    const Pose& p = s.placed;
    std::snprintf(numbers, sizeof numbers, ",%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,", p.x, p.y, p.z,
                  rad2deg(p.roll), rad2deg(p.pitch), rad2deg(p.yaw));
    out +=
        std::to_string(s.id) + "," + csv_field(s.robot) + numbers + csv_field(s.received_at) + "\n";
  }
  return out;
}

std::string annotations_geojson(const std::vector<Annotation>& annotations) {
  nlohmann::json features = nlohmann::json::array();
  for (const Annotation& a : annotations) {
    features.push_back(
        {{"type", "Feature"},
         {"id", a.id},
         {"geometry", {{"type", "Point"}, {"coordinates", {a.x, a.y, a.z}}}},
         {"properties",
          {{"kind", a.kind}, {"text", a.text}, {"by", a.author}, {"created_at", a.created_at}}}});
  }
  return nlohmann::json{{"type", "FeatureCollection"},
                        {"scanplan_frame",
                         "map: metres in the first scan's frame (origin at its position, x "
                         "along its heading, z up), not longitude and latitude"},
                        {"features", features}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace scanplan::server
