#include "scanplan/core/world.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace scanplan {
namespace {

using nlohmann::json;

// Reads one JSON object strictly: every access names its field, and keys nobody asked for
// are reported at the end, because a misspelt key silently falling back to a default is how
// a simulated world ends up different from the one its author wrote.
class Fields {
 public:
  Fields(const json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) fail("", "must be a JSON object");
  }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw WorldError(where_ + (field.empty() ? "" : ": field '" + field + "'") + " " + what);
  }

  bool has(const std::string& key) const { return j_.contains(key); }

  const json& raw(const std::string& key) {
    used_.insert(key);
    if (!j_.contains(key)) fail(key, "is missing");
    return j_.at(key);
  }

  double number(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_number()) fail(key, "must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "must be finite");
    return d;
  }
  double number_or(const std::string& key, double fallback) {
    return has(key) ? number(key) : (used_.insert(key), fallback);
  }
  double positive(const std::string& key, double fallback) {
    const double d = number_or(key, fallback);
    if (!(d > 0)) fail(key, "must be greater than zero");
    return d;
  }

  std::string string(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_string()) fail(key, "must be a string");
    return v.get<std::string>();
  }

  std::vector<double> numbers(const std::string& key, std::size_t n) {
    const json& v = raw(key);
    if (!v.is_array() || v.size() != n) fail(key, "must be an array of " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (const auto& e : v) {
      if (!e.is_number() || !std::isfinite(e.get<double>())) fail(key, "must hold finite numbers only");
      out.push_back(e.get<double>());
    }
    return out;
  }

  Rgb color(const std::string& key, Rgb fallback) {
    if (!has(key)) return used_.insert(key), fallback;
    const auto c = numbers(key, 3);
    Rgb rgb{};
    for (int i = 0; i < 3; ++i) {
      if (c[i] < 0 || c[i] > 255) fail(key, "components must be within 0..255");
      rgb[i] = static_cast<std::uint8_t>(std::lround(c[i]));
    }
    return rgb;
  }

  void no_unknown_keys() const {
    for (const auto& [key, value] : j_.items()) {
      if (!used_.count(key)) fail(key, "is not a known field");
    }
  }

 private:
  const json& j_;
  std::string where_;
  std::set<std::string> used_;
};

WorldBox parse_box(Fields& f) {
  WorldBox b;
  const auto mn = f.numbers("min", 3), mx = f.numbers("max", 3);
  b.min = {mn[0], mn[1], mn[2]};
  b.max = {mx[0], mx[1], mx[2]};
  if (!(b.max.array() > b.min.array()).all()) f.fail("max", "must exceed 'min' in x, y and z");
  b.yaw = deg2rad(f.number_or("yaw_deg", 0.0));
  b.color = f.color("color", b.color);
  return b;
}

void parse_scanner(Fields& f, ScannerConfig& s) {
  s.vertical_fov_deg = f.positive("vertical_fov_deg", s.vertical_fov_deg);
  s.vertical_step_deg = f.positive("vertical_step_deg", s.vertical_step_deg);
  s.rotation_deg = f.positive("rotation_deg", s.rotation_deg);
  s.rotation_step_deg = f.positive("rotation_step_deg", s.rotation_step_deg);
  s.min_range_m = f.number_or("min_range_m", s.min_range_m);
  s.max_range_m = f.positive("max_range_m", s.max_range_m);
  s.range_noise_m = f.number_or("range_noise_m", s.range_noise_m);
  s.mount_height_m = f.positive("mount_height_m", s.mount_height_m);
  s.scan_duration_s = f.number_or("scan_duration_s", s.scan_duration_s);
  if (s.vertical_fov_deg > 360 || s.rotation_deg > 360) f.fail("", "angles must not exceed 360°");
  if (s.min_range_m < 0 || s.min_range_m >= s.max_range_m)
    f.fail("min_range_m", "must be within [0, max_range_m)");
  if (s.range_noise_m < 0) f.fail("range_noise_m", "must not be negative");
  if (s.scan_duration_s < 0) f.fail("scan_duration_s", "must not be negative");
  f.no_unknown_keys();
}

void parse_pose_noise(Fields& f, PoseNoise& n) {
  n.xy_sigma_m = f.number_or("xy_sigma_m", n.xy_sigma_m);
  n.z_sigma_m = f.number_or("z_sigma_m", n.z_sigma_m);
  n.yaw_sigma_deg = f.number_or("yaw_sigma_deg", n.yaw_sigma_deg);
  if (n.xy_sigma_m < 0 || n.z_sigma_m < 0 || n.yaw_sigma_deg < 0)
    f.fail("", "sigmas must not be negative");
  f.no_unknown_keys();
}

}  // namespace

World parse_world(const std::string& json_text, const std::string& source_name) {
  json j;
  try {
    j = json::parse(json_text);
  } catch (const json::parse_error& e) {
    throw WorldError(source_name + ": not valid JSON: " + e.what());
  }
  World w;
  Fields top(j, source_name);
  w.name = top.string("name");

  Fields bounds(top.raw("bounds"), source_name + ": bounds");
  const auto bmin = bounds.numbers("min", 2), bmax = bounds.numbers("max", 2);
  w.bounds_min = {bmin[0], bmin[1]};
  w.bounds_max = {bmax[0], bmax[1]};
  if (!(w.bounds_max.array() > w.bounds_min.array()).all()) bounds.fail("max", "must exceed 'min'");
  bounds.no_unknown_keys();

  Fields ground(top.raw("ground"), source_name + ": ground");
  w.ground_z = ground.number("z");
  w.ground_color = ground.color("color", w.ground_color);
  ground.no_unknown_keys();

  const json& objects = top.raw("objects");
  if (!objects.is_array()) top.fail("objects", "must be an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const std::string where = source_name + ": objects[" + std::to_string(i) + "]";
    Fields f(objects[i], where);
    const std::string type = f.string("type");
    Fields typed(objects[i], where + " (" + type + ")");
    typed.raw("type");
    if (type == "box") {
      w.boxes.push_back(parse_box(typed));
    } else {
      typed.fail("type", "'" + type + "' is not a known object type (known: box)");
    }
    typed.no_unknown_keys();
  }

  const auto start = top.numbers("start", 3);
  w.start.x = start[0];
  w.start.y = start[1];
  w.start.z = w.ground_z;
  w.start.yaw = deg2rad(start[2]);

  if (top.has("scanner")) {
    Fields s(top.raw("scanner"), source_name + ": scanner");
    parse_scanner(s, w.scanner);
  }
  if (top.has("pose_noise")) {
    Fields n(top.raw("pose_noise"), source_name + ": pose_noise");
    parse_pose_noise(n, w.pose_noise);
  }
  top.no_unknown_keys();
  return w;
}

World load_world(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw WorldError(file.string() + ": cannot open the world file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_world(ss.str(), file.string());
}

}  // namespace scanplan
