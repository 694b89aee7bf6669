#include "scanplan/sim/world.hpp"

#include "scanplan/geometry/target_region.hpp"

#include <algorithm>
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

  double positive(const std::string& key) {
    const double d = number(key);
    if (!(d > 0)) fail(key, "must be greater than zero");
    return d;
  }

  long long integer(const std::string& key, long long lo, long long hi) {
    const json& v = raw(key);
    if (!v.is_number_integer()) fail(key, "must be a whole number");
    const long long n = v.get<long long>();
    if (n < lo || n > hi)
      fail(key, "must be within " + std::to_string(lo) + ".." + std::to_string(hi));
    return n;
  }

  std::string string(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_string()) fail(key, "must be a string");
    return v.get<std::string>();
  }

  std::vector<double> numbers(const std::string& key, std::size_t n) {
    const json& v = raw(key);
    if (!v.is_array() || v.size() != n)
      fail(key, "must be an array of " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (const auto& e : v) {
      if (!e.is_number() || !std::isfinite(e.get<double>()))
        fail(key, "must hold finite numbers only");
      out.push_back(e.get<double>());
    }
    return out;
  }

  Eigen::Vector2d vec2(const std::string& key) {
    const auto v = numbers(key, 2);
    return {v[0], v[1]};
  }
  Eigen::Vector3d vec3(const std::string& key) {
    const auto v = numbers(key, 3);
    return {v[0], v[1], v[2]};
  }
  Eigen::Vector3d positive_vec3(const std::string& key) {
    const Eigen::Vector3d v = vec3(key);
    if (!(v.array() > 0).all()) fail(key, "must hold three numbers greater than zero");
    return v;
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
  b.min = f.vec3("min");
  b.max = f.vec3("max");
  if (!(b.max.array() > b.min.array()).all()) f.fail("max", "must exceed 'min' in x, y and z");
  b.yaw = deg2rad(f.number_or("yaw_deg", 0.0));
  b.color = f.color("color", b.color);
  return b;
}

WorldCylinder parse_cylinder(Fields& f) {
  WorldCylinder c;
  c.center = f.vec2("center");
  const auto z = f.numbers("z", 2);
  c.z_min = z[0];
  c.z_max = z[1];
  if (!(c.z_max > c.z_min)) f.fail("z", "must be [bottom, top] with top above bottom");
  c.radius_m = f.positive("radius");
  c.color = f.color("color", c.color);
  return c;
}

WorldEllipsoid parse_ellipsoid(Fields& f) {
  WorldEllipsoid e;
  e.center = f.vec3("center");
  e.radii = f.positive_vec3("radii");
  e.color = f.color("color", e.color);
  return e;
}

WorldTree parse_tree(Fields& f) {
  WorldTree t;
  t.base = f.vec3("base");
  t.trunk_radius_m = f.positive("trunk_radius");
  t.trunk_height_m = f.positive("trunk_height");
  t.canopy_radii = f.positive_vec3("canopy_radii");
  t.color = f.color("color", t.color);
  t.trunk_color = f.color("trunk_color", t.trunk_color);
  return t;
}

WorldRamp parse_ramp(Fields& f) {
  WorldRamp r;
  r.min = f.vec3("min");
  r.max = f.vec3("max");
  if (!(r.max.array() > r.min.array()).all())
    f.fail("max", "must exceed 'min' in x, y and z (the top rises from min.z to max.z)");
  const std::string axis = f.string("rise_axis");
  if (axis == "x") {
    r.rise_axis = 0;
  } else if (axis == "y") {
    r.rise_axis = 1;
  } else {
    f.fail("rise_axis", "must be \"x\" or \"y\", not \"" + axis + "\"");
  }
  r.color = f.color("color", r.color);
  return r;
}

void parse_bounds(Fields& f, World& w) {
  const bool box = f.has("min") || f.has("max");
  if (box && f.has("polygon")) f.fail("polygon", "cannot be combined with 'min'/'max': give one");
  if (!box && !f.has("polygon")) f.fail("", "needs either 'min' and 'max' or a 'polygon'");
  if (box) {
    w.bounds_min = f.vec2("min");
    w.bounds_max = f.vec2("max");
    if (!(w.bounds_max.array() > w.bounds_min.array()).all()) f.fail("max", "must exceed 'min'");
    return;
  }
  const json& poly = f.raw("polygon");
  if (!poly.is_array() || poly.size() < 3)
    f.fail("polygon", "must be an array of at least 3 [x, y] vertices");
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const json& v = poly[i];
    const bool ok = v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number() &&
                    std::isfinite(v[0].get<double>()) && std::isfinite(v[1].get<double>());
    if (!ok)
      f.fail("polygon", "vertex " + std::to_string(i) + " must be [x, y] with finite numbers");
    w.bounds_polygon.emplace_back(v[0].get<double>(), v[1].get<double>());
  }
  double twice_area = 0;
  w.bounds_min = w.bounds_max = w.bounds_polygon.front();
  for (std::size_t i = 0; i < w.bounds_polygon.size(); ++i) {
    const Eigen::Vector2d& a = w.bounds_polygon[i];
    const Eigen::Vector2d& b = w.bounds_polygon[(i + 1) % w.bounds_polygon.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
    w.bounds_min = w.bounds_min.cwiseMin(a);
    w.bounds_max = w.bounds_max.cwiseMax(a);
  }
  if (!(std::abs(twice_area) > 0)) f.fail("polygon", "encloses no area");
}

void parse_ground(Fields& f, const std::string& where, World& w) {
  if (f.has("z") && f.has("grid")) f.fail("grid", "cannot be combined with 'z': give one of them");
  if (!f.has("z") && !f.has("grid"))
    f.fail("", "needs either 'z' (a flat ground) or 'grid' (heights on a lattice)");
  if (f.has("z")) {
    w.ground_z = f.number("z");
  } else {
    Fields g(f.raw("grid"), where + ": grid");
    const Eigen::Vector2d origin = g.vec2("origin");
    const double cell_m = g.positive("cell");
    // The cap keeps a typo from asking for terabytes before the height count is checked.
    constexpr long long kMaxNodes = 100000;
    const auto cols = static_cast<int>(g.integer("cols", 2, kMaxNodes));
    const auto rows = static_cast<int>(g.integer("rows", 2, kMaxNodes));
    const std::size_t count = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
    std::vector<double> z = g.numbers("z", count);
    g.no_unknown_keys();
    try {
      w.ground_grid.emplace(origin, cell_m, cols, rows, std::move(z));
    } catch (const std::invalid_argument& e) {
      g.fail("", e.what());
    }
  }
  w.ground_color = f.color("color", w.ground_color);
  f.no_unknown_keys();
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
  const double width = f.number_or("camera_width_px", s.camera_width_px);
  if (width < 16 || width > 16384 || width != std::floor(width) || std::fmod(width, 2) != 0) {
    f.fail("camera_width_px", "must be an even whole number of pixels within 16..16384");
  }
  s.camera_width_px = static_cast<int>(width);
  s.camera_above_laser_m = f.number_or("camera_above_laser_m", s.camera_above_laser_m);
  const double quality = f.number_or("camera_jpeg_quality", s.camera_jpeg_quality);
  if (quality < 1 || quality > 100) f.fail("camera_jpeg_quality", "must be within 1..100");
  s.camera_jpeg_quality = static_cast<int>(quality);
  if (s.vertical_fov_deg > 360 || s.rotation_deg > 360) f.fail("", "angles must not exceed 360°");
  if (s.min_range_m < 0 || s.min_range_m >= s.max_range_m)
    f.fail("min_range_m", "must be within [0, max_range_m)");
  if (s.range_noise_m < 0) f.fail("range_noise_m", "must not be negative");
  if (s.scan_duration_s < 0) f.fail("scan_duration_s", "must not be negative");
  f.no_unknown_keys();
}

void parse_pose_noise(Fields& f, PoseNoise& n) {
  if (f.has("model")) {
    const std::string name = f.string("model");
    const auto model = parse_odometry_model(name);
    if (!model) f.fail("model", "must be \"drift\" or \"absolute\", not \"" + name + "\"");
    n.model = *model;
  }
  n.xy_sigma_m = f.number_or("xy_sigma_m", n.xy_sigma_m);
  n.z_sigma_m = f.number_or("z_sigma_m", n.z_sigma_m);
  n.yaw_sigma_deg = f.number_or("yaw_sigma_deg", n.yaw_sigma_deg);
  n.xy_drift_fraction = f.number_or("xy_drift_fraction", n.xy_drift_fraction);
  n.yaw_drift_deg_per_10m = f.number_or("yaw_drift_deg_per_10m", n.yaw_drift_deg_per_10m);
  n.z_drift_fraction = f.number_or("z_drift_fraction", n.z_drift_fraction);
  if (n.xy_sigma_m < 0 || n.z_sigma_m < 0 || n.yaw_sigma_deg < 0 || n.xy_drift_fraction < 0 ||
      n.yaw_drift_deg_per_10m < 0 || n.z_drift_fraction < 0)
    f.fail("", "sigmas must not be negative");
  f.no_unknown_keys();
}

}  // namespace

double WorldRamp::top_z(double x, double y) const {
  const double s = rise_axis == 0 ? x : y;
  const double s0 = min[rise_axis], s1 = max[rise_axis];
  const double f = std::clamp((s - s0) / (s1 - s0), 0.0, 1.0);
  return min.z() + f * (max.z() - min.z());
}

double World::ground_height(double x, double y) const {
  return ground_grid ? ground_grid->height(x, y) : ground_z;
}

bool World::in_target_region(double x, double y) const {
  if (x < bounds_min.x() || x > bounds_max.x() || y < bounds_min.y() || y > bounds_max.y())
    return false;
  return bounds_polygon.empty() || polygon_contains(bounds_polygon, x, y);
}

TargetRegion World::target_region() const {
  if (!bounds_polygon.empty()) return TargetRegion::polygon(bounds_polygon);
  return TargetRegion::rectangle(bounds_min, bounds_max);
}

World parse_world(const std::string& json_text, const std::string& source_name) {
  json j;
  try {
    j = json::parse(json_text);
  } catch (const json::exception& e) {
    // Not only parse_error: a number too large for a double (1e999) is out_of_range.
    throw WorldError(source_name + ": not valid JSON: " + e.what());
  }
  World w;
  Fields top(j, source_name);
  w.name = top.string("name");

  Fields bounds(top.raw("bounds"), source_name + ": bounds");
  parse_bounds(bounds, w);
  bounds.no_unknown_keys();

  Fields ground(top.raw("ground"), source_name + ": ground");
  parse_ground(ground, source_name + ": ground", w);

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
    } else if (type == "cylinder") {
      w.cylinders.push_back(parse_cylinder(typed));
    } else if (type == "ellipsoid") {
      w.ellipsoids.push_back(parse_ellipsoid(typed));
    } else if (type == "tree") {
      w.trees.push_back(parse_tree(typed));
    } else if (type == "ramp") {
      w.ramps.push_back(parse_ramp(typed));
    } else {
      typed.fail("type", "'" + type +
                             "' is not a known object type (known: box, cylinder, ellipsoid, "
                             "tree, ramp)");
    }
    typed.no_unknown_keys();
  }

  const auto start = top.numbers("start", 3);
  w.start.x = start[0];
  w.start.y = start[1];
  w.start.z = w.ground_height(w.start.x, w.start.y);
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
