#include "scanplan/planning/visibility.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "digest.hpp"
#include "fast_atan.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan {
namespace {

// Far below anything: the bottom of a solid column, with finite slopes from any distance.
constexpr float kSolid = 1e6f;

}  // namespace

VisibilityConfig VisibilityConfig::from_scanner(const ScannerConfig& scanner) {
  VisibilityConfig c;
  c.max_range_m = scanner.max_range_m;
  c.min_range_m = scanner.min_range_m;
  c.sensor_height_m = scanner.mount_height_m;
  c.elevation_step_deg = scanner.vertical_step_deg;
  c.vertical_fov_deg = scanner.vertical_fov_deg;
  return c;
}

namespace {

void check_config(const VisibilityConfig& c) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("visibility config: " + what);
  };
  if (!(c.azimuth_step_deg > 0 && c.azimuth_step_deg <= 90)) {
    fail("azimuth_step_deg must be in (0, 90], got " + std::to_string(c.azimuth_step_deg));
  }
  if (!(c.elevation_step_deg > 0 && c.elevation_step_deg <= 90)) {
    fail("elevation_step_deg must be in (0, 90], got " + std::to_string(c.elevation_step_deg));
  }
  if (!(c.vertical_fov_deg > 0 && c.vertical_fov_deg <= 180)) {
    fail("vertical_fov_deg must be in (0, 180], got " + std::to_string(c.vertical_fov_deg));
  }
  // The walk stores cell offsets in 16 bits.
  if (!(c.max_range_m > 0 && c.max_range_m <= 10000)) {
    fail("max_range_m must be in (0, 10000], got " + std::to_string(c.max_range_m));
  }
  if (!(c.min_range_m >= 0 && c.min_range_m < c.max_range_m)) {
    fail("min_range_m must be in [0, max_range_m), got " + std::to_string(c.min_range_m));
  }
  if (!std::isfinite(c.sensor_height_m)) fail("sensor_height_m must be finite");
  if (!(c.max_ray_spacing_m > 0)) {
    fail("max_ray_spacing_m must be greater than zero, got " + std::to_string(c.max_ray_spacing_m));
  }
  if (c.vertical_fov_deg / c.elevation_step_deg > 2000) {
    fail("the fan has more than 2000 beams (vertical_fov_deg / elevation_step_deg)");
  }
}

}  // namespace

VisibilityPredictor::VisibilityPredictor(const MlsMap& map, CellIndex raster_origin,
                                         int raster_cols, int raster_rows,
                                         const VisibilityConfig& config,
                                         const Eigen::Vector2d& sensor_offset)
    : config_(config),
      cell_m_(map.cell_m()),
      fill_(map.config().fill_between_beams),
      fill_max_gap_(static_cast<float>(map.config().fill_max_gap_m)),
      fill_max_slope_(static_cast<float>(map.config().fill_max_slope)),
      raster_origin_(raster_origin),
      raster_cols_(raster_cols),
      raster_rows_(raster_rows) {
  check_config(config);
  if (raster_cols <= 0 || raster_rows <= 0) {
    throw std::invalid_argument("visibility: the raster has no cells");
  }
  if (!(sensor_offset.array() >= 0).all() || !(sensor_offset.array() < 1).all()) {
    throw std::invalid_argument("visibility: the sensor offset must be within its cell, in [0, 1)");
  }

  // The vertical fan exactly as ScannerConfig::vertical_samples counts it.
  beams_ =
      static_cast<int>(std::floor(config.vertical_fov_deg / config.elevation_step_deg + 1e-9)) + 1;
  el0_ = static_cast<float>(deg2rad(-config.vertical_fov_deg / 2));
  inv_el_step_ = static_cast<float>(1.0 / deg2rad(config.elevation_step_deg));
  slope_.resize(static_cast<std::size_t>(beams_));
  inv_slope_.resize(static_cast<std::size_t>(beams_));
  for (int k = 0; k < beams_; ++k) {
    const auto u = static_cast<std::size_t>(k);
    slope_[u] = static_cast<float>(
        std::tan(deg2rad(-config.vertical_fov_deg / 2 + k * config.elevation_step_deg)));
    inv_slope_[u] = 1.0f / slope_[u];
  }

  // Sensors may stand anywhere over the map or the raster.
  sensor_min_ = raster_origin;
  sensor_max_ = {raster_origin.x + raster_cols - 1, raster_origin.y + raster_rows - 1};
  if (const auto extent = map.extent()) {
    sensor_min_ = {std::min(sensor_min_.x, extent->first.x),
                   std::min(sensor_min_.y, extent->first.y)};
    sensor_max_ = {std::max(sensor_max_.x, extent->second.x),
                   std::max(sensor_max_.y, extent->second.y)};
  }
  build_dense(map);
  sensor_offset_ = sensor_offset;
  if (config.thin_object_radius_m > 0) find_thin_objects();
  build_rays(sensor_offset);
  deltas_.reserve(steps_.size());
  for (const Step& st : steps_) deltas_.push_back(st.dense_delta);
}

void VisibilityPredictor::build_dense(const MlsMap& map) {
  const int pad = static_cast<int>(std::ceil(config_.max_range_m / cell_m_)) + 2;
  dense_origin_ = {sensor_min_.x - pad, sensor_min_.y - pad};
  dense_cols_ = sensor_max_.x - sensor_min_.x + 1 + 2 * pad;
  dense_rows_ = sensor_max_.y - sensor_min_.y + 1 + 2 * pad;
  dense_.resize(static_cast<std::size_t>(dense_cols_) * dense_rows_);
  patches_.resize(dense_.size());
  max_z_ = std::numeric_limits<float>::lowest();
  map.for_each_cell([&](CellIndex c, const MlsCell& cell) {
    const int i = c.x - dense_origin_.x, j = c.y - dense_origin_.y;
    if (i < 0 || j < 0 || i >= dense_cols_ || j >= dense_rows_) return;
    const std::size_t o = static_cast<std::size_t>(j) * dense_cols_ + i;
    DenseCell& d = dense_[o];
    d.n = static_cast<std::int16_t>(cell.size);
    d.lo0 = cell.patches[0].min_z;
    d.hi0 = cell.patches[0].max_z;
    d.top = cell.dem_height();
    for (int k = 0; k < cell.size; ++k) {
      patches_[o][2 * k] = cell.patches[k].min_z;
      patches_[o][2 * k + 1] = cell.patches[k].max_z;
    }
    max_z_ = std::max(max_z_, d.top);
  });
}

void VisibilityPredictor::build_rays(const Eigen::Vector2d& sensor_offset) {
  const VisibilityConfig& config = config_;
  // The ray tree. Rays 2^l azimuth steps apart are max_ray_spacing_m apart at reach(l);
  // level l covers the distances from reach(l + 1) to reach(l), the finest level everything
  // beyond. A level-l ray stands for the 2^l finest azimuths of its sector and sits at their
  // middle, so what it sees is spread evenly to the rays it splits into. Levels stop where
  // the azimuths no longer halve or a level would cover less than two cells.
  const int n_az = std::max(1, static_cast<int>(std::lround(360.0 / config.azimuth_step_deg)));
  azimuths_ = n_az;
  const double step_rad = 2 * M_PI / n_az;
  const auto reach = [&](int l) { return config.max_ray_spacing_m / (step_rad * (1 << l)); };
  levels_ = 0;
  while (levels_ < 6 && n_az % (2 << levels_) == 0 && reach(levels_ + 1) >= 2 * cell_m_) ++levels_;
  level_offset_.assign(static_cast<std::size_t>(levels_) + 1, 0);
  for (int l = 0; l <= levels_; ++l) {
    level_offset_[static_cast<std::size_t>(l)] = static_cast<std::uint32_t>(rays_.size());
    const double from = l == levels_ ? 0.0 : reach(l + 1);
    const double to = l == 0 ? config.max_range_m : reach(l);
    for (int m = 0; m < n_az >> l; ++m) {
      const double az = step_rad * (m * (1 << l) + ((1 << l) - 1) / 2.0);
      Ray ray;
      ray.dir = Eigen::Vector2f(static_cast<float>(std::cos(az)), static_cast<float>(std::sin(az)));
      ray.walk_begin = static_cast<std::uint32_t>(steps_.size());
      // The walk always starts at the sensor: filling between returns looks back along it.
      walk(az, to / cell_m_, sensor_offset);
      ray.walk_end = static_cast<std::uint32_t>(steps_.size());
      ray.segment_begin = ray.walk_begin;
      while (ray.segment_begin < ray.walk_end && steps_[ray.segment_begin].d0 < from)
        ++ray.segment_begin;
      rays_.push_back(ray);
    }
  }
}

void VisibilityPredictor::walk(double az, double reach_cells, const Eigen::Vector2d& offset) {
  // Amanatides & Woo through the cells, from the sensor's place in its cell. Every sensor
  // stands at the same place in its cell, so one walk per ray serves every candidate.
  const double cx = std::cos(az), cy = std::sin(az);
  const double inf = std::numeric_limits<double>::infinity();
  const int sx = cx > 0 ? 1 : -1, sy = cy > 0 ? 1 : -1;
  double t_max_x = cx > 1e-12 ? (1 - offset.x()) / cx : cx < -1e-12 ? offset.x() / -cx : inf;
  double t_max_y = cy > 1e-12 ? (1 - offset.y()) / cy : cy < -1e-12 ? offset.y() / -cy : inf;
  const double dt_x = std::abs(cx) > 1e-12 ? 1 / std::abs(cx) : inf;
  const double dt_y = std::abs(cy) > 1e-12 ? 1 / std::abs(cy) : inf;
  int i = 0, j = 0;
  double t = 0;
  while (t < reach_cells) {
    const double t_exit = std::min(t_max_x, t_max_y);
    if (t_exit - t > 1e-9) {
      Step s;
      s.dense_delta = j * dense_cols_ + i;
      s.di = static_cast<std::int16_t>(i);
      s.dj = static_cast<std::int16_t>(j);
      s.d0 = static_cast<float>(t * cell_m_);
      s.d1 = static_cast<float>(t_exit * cell_m_);
      s.inv_d0 = t > 0 ? 1.0f / s.d0 : std::numeric_limits<float>::infinity();
      s.inv_d1 = 1.0f / s.d1;
      steps_.push_back(s);
    }
    if (t_max_x < t_max_y) {
      i += sx;
      t = t_max_x;
      t_max_x += dt_x;
    } else {
      j += sy;
      t = t_max_y;
      t_max_y += dt_y;
    }
  }
}

void VisibilityPredictor::find_thin_objects() {
  // Standing cells: the lowest patch is deeper than any floor or kerb. Their 8-connected groups
  // that fit in 2 × 2 cells are thin objects, centred on the group's middle: a post standing
  // on a cell corner leaves its points in all four cells around it.
  const float deep = static_cast<float>(2 * config_.ground_max_extent_m);
  // A deep patch hanging above its neighbours' ground (a canopy whose ground was not seen) is
  // not standing on anything.
  const float jump = static_cast<float>(config_.ground_max_jump_m);
  std::vector<std::uint8_t> standing(dense_.size(), 0);
  for (int j = 1; j + 1 < dense_rows_; ++j) {
    for (int i = 1; i + 1 < dense_cols_; ++i) {
      const std::size_t o = static_cast<std::size_t>(j) * dense_cols_ + i;
      const DenseCell& d = dense_[o];
      if (d.n == 0 || d.hi0 - d.lo0 <= deep) continue;
      float ground = d.lo0;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const DenseCell& n = dense_[o + static_cast<std::ptrdiff_t>(dj) * dense_cols_ + di];
          if (n.n > 0) ground = std::min(ground, n.lo0);
        }
      }
      standing[o] = d.lo0 <= ground + jump;
    }
  }
  std::vector<std::int32_t> group, open;
  for (std::size_t o = 0; o < dense_.size(); ++o) {
    if (standing[o] != 1) continue;
    group.clear();
    open.assign(1, static_cast<std::int32_t>(o));
    standing[o] = 2;
    int i_min = dense_cols_, i_max = -1, j_min = dense_rows_, j_max = -1;
    while (!open.empty()) {
      const std::int32_t c = open.back();
      open.pop_back();
      group.push_back(c);
      const int i = c % dense_cols_, j = c / dense_cols_;
      i_min = std::min(i_min, i);
      i_max = std::max(i_max, i);
      j_min = std::min(j_min, j);
      j_max = std::max(j_max, j);
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int ni = i + di, nj = j + dj;
          if (ni < 0 || nj < 0 || ni >= dense_cols_ || nj >= dense_rows_) continue;
          const std::size_t n = static_cast<std::size_t>(nj) * dense_cols_ + ni;
          if (standing[n] != 1) continue;
          standing[n] = 2;
          open.push_back(static_cast<std::int32_t>(n));
        }
      }
    }
    if (i_max - i_min > 1 || j_max - j_min > 1 ||
        thin_centres_.size() >= static_cast<std::size_t>(std::numeric_limits<std::int16_t>::max()))
      continue;
    const float cx = static_cast<float>((i_min + i_max + 1) * 0.5 * cell_m_);
    const float cy = static_cast<float>((j_min + j_max + 1) * 0.5 * cell_m_);
    for (const std::int32_t c : group)
      dense_[static_cast<std::size_t>(c)].thin = static_cast<std::int16_t>(thin_centres_.size());
    thin_centres_.emplace_back(cx, cy);
  }
}

VisibilityPredictor::Workspace VisibilityPredictor::workspace() const {
  Workspace ws;
  ws.stamp.assign(static_cast<std::size_t>(raster_cols_) * raster_rows_, 0);
  return ws;
}

struct VisibilityPredictor::Trace {
  float sz, floor, ceiling, min_r2, max_r2, ground_extent, ground_jump, min_fill, min_clip;
  float thin_radius;
  std::size_t base;           // the sensor's cell in the dense map
  std::int64_t i0, j0;        // the sensor's cell in the raster
  Eigen::Vector2f sensor_xy;  // metres from the dense map's corner
  Eigen::Vector2f dir;        // of the ray being traced
  float half_spacing;         // half the angle to the neighbouring rays at this level
};

struct VisibilityPredictor::RayState {
  std::uint64_t free[kMaxBeamWords];  // beams not yet stopped
  int k_min, k_max;                   // the lowest and highest of them
  float ground;                       // the ground height carried along the ray
  bool done = false;  // nothing more to see along this ray or the rays it splits into
  // The previous return of a descending beam, for the gap filling between neighbours.
  bool have_last = false, last_usable = false;
  float last_d = 0, last_z = 0;
};

void VisibilityPredictor::mark(const Trace& t, const Step& s, Workspace& ws) const {
  const std::int64_t i = t.i0 + s.di, j = t.j0 + s.dj;
  if (i < 0 || j < 0 || i >= raster_cols_ || j >= raster_rows_) return;
  const std::size_t o = static_cast<std::size_t>(j) * raster_cols_ + static_cast<std::size_t>(i);
  if (ws.stamp[o] == ws.epoch) return;
  ws.stamp[o] = ws.epoch;
  ws.visible.push_back(static_cast<std::uint32_t>(o));
}

// One ray's walk outward through the cells (trace), step by step: which free beams each cell's
// surfaces stop, the returns they leave, and the ground filled between them. The parts are
// forced inline: this is the planner's innermost loop (docs/benchmarks.md planner_campus).
struct VisibilityPredictor::Tracer {
  const VisibilityPredictor& vp;
  const Trace& t;
  RayState& st;
  Workspace& ws;
  const float* slope;
  const float* inv_slope;
  const Step* walk;  // the ray's first step, at the sensor
  float sz;

  // Where beam k, known to cross the patch [lo, hi] of the cell entered at d0, first meets it.
  [[gnu::always_inline]] void landing(int k, float d0, float lo, float hi, float& d,
                                      float& z) const {
    const float tk = slope[k];
    const float z0 = sz + tk * d0;
    if (tk < 0 && z0 > hi) {  // comes down onto the top
      d = (hi - sz) * inv_slope[k];
      z = hi;
    } else if (tk > 0 && z0 < lo) {  // rises into the underside
      d = (lo - sz) * inv_slope[k];
      z = lo;
    } else {  // the side
      d = d0;
      z = z0;
    }
  }

  [[gnu::always_inline]] bool in_range(float d, float z) const {
    const float r2 = d * d + (z - sz) * (z - sz);
    return r2 >= t.min_r2 && r2 <= t.max_r2;
  }

  // insert_scan's rule for filling between two neighbouring returns of a fan: both below the
  // laser and off its axis, no closer than a cell and no farther than fill_max_gap_m, gently
  // sloped. Returns come here in distance order, which for descending beams is beam order.
  [[gnu::always_inline]] void chain(const Step* s, float d0, float z0, float d1, float z1) {
    const bool usable = z0 < sz && d0 > 0.3f;
    if (vp.fill_ && st.have_last && st.last_usable && usable && d0 > st.last_d) {
      const float length = d0 - st.last_d;
      if (length >= t.min_fill && length <= vp.fill_max_gap_ &&
          std::abs(z0 - st.last_z) <= vp.fill_max_slope_ * length) {
        for (const Step* p = s - 1; p >= walk && p->d0 >= st.last_d; --p) {
          // A corner the walk only clips is usually missed by the fill's half-cell samples.
          if (p->d1 - p->d0 >= t.min_clip) vp.mark(t, *p, ws);
        }
      }
    }
    st.have_last = true;
    st.last_usable = z1 < sz && d1 > 0.3f;
    st.last_d = d1;
    st.last_z = z1;
  }

  // The surfaces of the cell entered at `s` that stop beams, as [lo, hi] pairs into `lo_hi`;
  // returns how many.
  [[gnu::always_inline]] int surfaces(const Step& s, std::size_t at, const DenseCell& cell,
                                      bool assume, bool hanging, float* lo_hi) const {
    int n = 0;
    if (assume && vp.config_.unknown_as_ground) {
      lo_hi[0] = -kSolid;
      lo_hi[1] = st.ground;
      n = 1;
    }
    for (int p = 0; p < cell.n; ++p) {
      lo_hi[2 * n] = vp.patches_[at][2 * p];
      lo_hi[2 * n + 1] = vp.patches_[at][2 * p + 1];
      ++n;
    }
    if (!hanging) {
      lo_hi[0] = -kSolid;
      // A ray passing beside a thin object meets only the ground at its foot.
      if (cell.thin >= 0) {
        const Eigen::Vector2f rel =
            vp.thin_centres_[static_cast<std::size_t>(cell.thin)] - t.sensor_xy;
        // At least half the gap to the neighbouring rays, or an object between two rays
        // would stop neither.
        const float radius = std::max(t.thin_radius, s.d0 * t.half_spacing);
        if (std::abs(rel.x() * t.dir.y() - rel.y() * t.dir.x()) > radius) lo_hi[1] = cell.lo0;
      }
    }
    return n;
  }

  // The free beams whose slopes lie in [t_lo, t_hi], as k0..k1; false when there are none.
  // Ground takes the lowest free beam and a few above it, found by walking the slope table;
  // atan only for tall spans.
  [[gnu::always_inline]] bool beams_between(float t_lo, float t_hi, int& k0, int& k1) const {
    k0 = st.k_min;
    if (t_lo > slope[k0]) {
      k0 = std::max(st.k_min,
                    static_cast<int>(std::ceil((fast_atan(t_lo) - vp.el0_) * vp.inv_el_step_)));
      while (k0 > st.k_min && slope[k0 - 1] >= t_lo) --k0;
      while (k0 <= st.k_max && slope[k0] < t_lo) ++k0;
      if (k0 > st.k_max) return false;
    }
    k1 = st.k_max;
    if (t_hi < slope[k1]) {
      k1 = k0 - 1;
      int walked = 0;
      while (walked < 8 && slope[k1 + 1] <= t_hi) {
        ++k1;
        ++walked;
      }
      if (walked == 8) {
        k1 = std::min(st.k_max,
                      static_cast<int>(std::floor((fast_atan(t_hi) - vp.el0_) * vp.inv_el_step_)));
        while (k1 < st.k_max && slope[k1 + 1] <= t_hi) ++k1;
        while (k1 >= k0 && slope[k1] > t_hi) --k1;
      }
    }
    return k0 <= k1;
  }

  struct Stops {
    bool seen = false;     // a return in range: the cell is seen
    bool stopped = false;  // some free beam ended here
  };

  // Ends the still-free beams among k0..k1 at the patch [lo, hi] of the cell entered at `s`.
  [[gnu::always_inline]] void stop_beams(const Step* s, float lo, float hi, int k0, int k1,
                                         Stops& out) {
    const int w0 = k0 >> 6, w1 = k1 >> 6;
    for (int w = w0; w <= w1; ++w) {
      std::uint64_t bits = st.free[w];
      if (w == w0) bits &= ~0ull << (k0 & 63);
      if (w == w1 && (k1 & 63) != 63) bits &= (1ull << ((k1 & 63) + 1)) - 1;
      if (!bits) continue;
      st.free[w] &= ~bits;
      out.stopped = true;
      // Each run of still-free beams ends here; the beams it stops leave no return beyond.
      while (bits) {
        const int b = std::countr_zero(bits);
        const std::uint64_t shifted = bits >> b;
        const int len = ~shifted == 0 ? 64 - b : std::countr_zero(~shifted);
        const int kf = 64 * w + b, kl = kf + len - 1;
        bits = b + len >= 64 ? 0 : bits & (~0ull << (b + len));
        float df, zf, dl, zl;
        landing(kf, s->d0, lo, hi, df, zf);
        landing(kl, s->d0, lo, hi, dl, zl);
        if (!in_range(df, zf) && !in_range(dl, zl)) continue;  // no return: no point
        out.seen = true;
        if (zf < sz) chain(s, df, zf, dl, zl);
      }
    }
  }

  // The lowest and highest free beams after some stopped; false when every beam has ended.
  [[gnu::always_inline]] bool narrow() {
    const auto is_free = [&](int k) { return (st.free[k >> 6] >> (k & 63)) & 1; };
    if (!is_free(st.k_min)) {
      int w = st.k_min >> 6;
      const int words = (vp.beams_ + 63) >> 6;
      while (w < words && st.free[w] == 0) ++w;
      if (w == words) return false;
      st.k_min = 64 * w + std::countr_zero(st.free[w]);
    }
    if (!is_free(st.k_max)) {
      int w = st.k_max >> 6;
      while (st.free[w] == 0) --w;
      st.k_max = 64 * w + 63 - std::countl_zero(st.free[w]);
    }
    return true;
  }

  // The cell entered at `s`; false when nothing more can be seen along this ray.
  [[gnu::always_inline]] bool step(const Step* s) {
    // Every beam still free passes above the highest surface anywhere: nothing more to see.
    if (slope[st.k_min] > 0 && slope[st.k_min] * s->d0 > t.ceiling) return false;
    const std::size_t at = t.base + static_cast<std::size_t>(s->dense_delta);
    const DenseCell& cell = vp.dense_[at];
    // Below the lowest surface of a cell the ground is solid (the measured top of a cell is a
    // few centimetres off its neighbour's, and a beam passing under it would slip beneath the
    // ground), unless that lowest one hangs well above the ground carried along the ray: then
    // it is a canopy or an overhang whose ground was not seen, assumed as for unknown cells.
    const bool hanging = cell.n > 0 && cell.lo0 > st.ground + t.ground_jump;
    const bool assume = cell.n == 0 || hanging;
    if (assume && !vp.config_.unknown_as_ground && cell.n == 0) return true;
    if (!assume && cell.hi0 - cell.lo0 <= t.ground_extent &&
        std::abs(cell.hi0 - st.ground) <= t.ground_jump) {
      st.ground = cell.hi0;
    }
    // Most cells lie wholly below the lowest free beam (ground already passed over).
    const float r_top = (cell.n == 0 ? st.ground : cell.top) - sz;
    if ((r_top > 0 ? r_top * s->inv_d0 : r_top * s->inv_d1) < slope[st.k_min]) return true;
    float lo_hi[2 * (MlsCell::kMaxPatches + 1)];
    const int n = surfaces(*s, at, cell, assume, hanging, lo_hi);
    Stops stops;
    for (int p = 0; p < n; ++p) {
      const float lo = lo_hi[2 * p], hi = lo_hi[2 * p + 1];
      // The beams crossing the box [d0, d1] × [lo, hi]: slopes between its extreme corners.
      const float rlo = lo - sz, rhi = hi - sz;
      const float t_lo = rlo < 0 ? rlo * s->inv_d0 : rlo * s->inv_d1;
      const float t_hi = rhi > 0 ? rhi * s->inv_d0 : rhi * s->inv_d1;
      if (t_hi < slope[st.k_min] || t_lo > slope[st.k_max]) continue;
      int k0, k1;
      if (beams_between(t_lo, t_hi, k0, k1)) stop_beams(s, lo, hi, k0, k1, stops);
    }
    if (stops.seen) vp.mark(t, *s, ws);
    return !stops.stopped || narrow();
  }
};

void VisibilityPredictor::trace(const Trace& tr, int level, int m, RayState& st,
                                Workspace& ws) const {
  const std::size_t index =
      level_offset_[static_cast<std::size_t>(level)] + static_cast<std::size_t>(m);
  const Ray& ray = rays_[index];
  // From the sensor: the gap filling marks cells back along the walk before this ray's part.
  const auto walked = [&](const Step* last) {
    ws.walked[index] = static_cast<std::uint8_t>(
        std::min<std::ptrdiff_t>(255, last - (steps_.data() + ray.walk_begin) + 1));
  };
  Trace t = tr;
  t.dir = ray.dir;
  t.half_spacing = static_cast<float>(0.5 * 2 * M_PI / azimuths_ * (1 << level));
  Tracer walker{*this, t, st, ws, slope_.data(), inv_slope_.data(), steps_.data() + ray.walk_begin,
                t.sz};
  const Step* end = steps_.data() + ray.walk_end;
  for (const Step* s = steps_.data() + ray.segment_begin; s != end; ++s) {
    if (!walker.step(s)) {
      walked(s);
      st.done = true;
      return;
    }
  }
  walked(end - 1);
  if (level == 0) return;
  // Split in two, each at the middle of one half of this ray's sector, both going on with
  // everything this one has seen so far.
  RayState other = st;
  trace(t, level - 1, 2 * m, st, ws);
  trace(t, level - 1, 2 * m + 1, other, ws);
}

const std::vector<std::uint32_t>& VisibilityPredictor::visible_from(CellIndex sensor,
                                                                    double floor_z,
                                                                    Workspace& ws) const {
  if (sensor.x < sensor_min_.x || sensor.y < sensor_min_.y || sensor.x > sensor_max_.x ||
      sensor.y > sensor_max_.y) {
    throw std::out_of_range("visibility: sensor cell (" + std::to_string(sensor.x) + ", " +
                            std::to_string(sensor.y) +
                            ") is outside the map and raster the predictor was built for");
  }
  if (!std::isfinite(floor_z))
    throw std::invalid_argument("visibility: floor height is not finite");
  if (ws.stamp.size() != static_cast<std::size_t>(raster_cols_) * raster_rows_) ws = workspace();
  if (++ws.epoch == 0) {
    std::fill(ws.stamp.begin(), ws.stamp.end(), 0);
    ws.epoch = 1;
  }
  ws.visible.clear();
  ws.walked.assign(rays_.size(), 0);

  Trace t;
  t.floor = static_cast<float>(floor_z);
  t.sz = static_cast<float>(floor_z + config_.sensor_height_m);
  // Nothing rises above this: a beam that clears it at some distance clears everything beyond.
  t.ceiling = std::max(max_z_, t.floor) - t.sz;
  t.min_r2 = static_cast<float>(config_.min_range_m * config_.min_range_m);
  t.max_r2 = static_cast<float>(config_.max_range_m * config_.max_range_m);
  t.ground_extent = static_cast<float>(config_.ground_max_extent_m);
  t.ground_jump = static_cast<float>(config_.ground_max_jump_m);
  t.min_fill = static_cast<float>(cell_m_);
  t.min_clip = static_cast<float>(0.25 * cell_m_);
  t.base = static_cast<std::size_t>(sensor.y - dense_origin_.y) * dense_cols_ +
           static_cast<std::size_t>(sensor.x - dense_origin_.x);
  t.i0 = sensor.x - raster_origin_.x;
  t.j0 = sensor.y - raster_origin_.y;
  t.thin_radius = static_cast<float>(config_.thin_object_radius_m);
  t.sensor_xy =
      ((Eigen::Vector2d(sensor.x - dense_origin_.x, sensor.y - dense_origin_.y) + sensor_offset_) *
       cell_m_)
          .cast<float>();

  RayState start;
  const int words = (beams_ + 63) >> 6;
  std::fill(std::begin(start.free), std::end(start.free), 0ull);
  for (int w = 0; w < words; ++w) start.free[w] = ~0ull;
  if (beams_ % 64) start.free[words - 1] = (1ull << (beams_ % 64)) - 1;
  start.k_min = 0;
  start.k_max = beams_ - 1;
  start.ground = t.floor;
  for (int m = 0; m < azimuths_ >> levels_; ++m) {
    RayState st = start;
    trace(t, levels_, m, st, ws);
  }
  return ws.visible;
}

using digest::mix;

std::uint64_t VisibilityPredictor::digest() const {
  const VisibilityConfig& c = config_;
  std::uint64_t h = 0x5CA9;
  for (const double v : {c.azimuth_step_deg, c.max_ray_spacing_m, c.max_range_m, c.sensor_height_m,
                         c.elevation_step_deg, c.vertical_fov_deg, c.min_range_m,
                         c.ground_max_extent_m, c.ground_max_jump_m, c.thin_object_radius_m,
                         cell_m_, sensor_offset_.x(), sensor_offset_.y()})
    h = mix(h, v);
  h = mix(h, static_cast<std::uint64_t>(c.unknown_as_ground) | (std::uint64_t{fill_} << 1));
  h = mix(mix(mix(h, fill_max_gap_), fill_max_slope_), max_z_);
  return mix(mix(h, static_cast<std::uint64_t>(beams_)), static_cast<std::uint64_t>(rays_.size()));
}

std::uint64_t VisibilityPredictor::cell_digest(std::size_t o) const {
  const DenseCell& d = dense_[o];
  std::uint64_t h = mix(std::uint64_t{0xCE11}, static_cast<std::uint64_t>(d.n));
  if (d.n == 0) return h;
  h = mix(mix(mix(h, d.lo0), d.hi0), d.top);
  for (int k = 0; k < 2 * d.n; ++k) h = mix(h, patches_[o][static_cast<std::size_t>(k)]);
  if (d.thin >= 0) {
    // Where the object stands in the world, not in this raster.
    const Eigen::Vector2f c = thin_centres_[static_cast<std::size_t>(d.thin)];
    h = mix(mix(h, c.x() + static_cast<double>(dense_origin_.x) * cell_m_),
            c.y() + static_cast<double>(dense_origin_.y) * cell_m_);
  }
  return h;
}

bool VisibilityPredictor::walks_reach(CellIndex sensor, const std::vector<std::uint8_t>& walks,
                                      const std::vector<std::uint32_t>& stamp,
                                      std::uint32_t since) const {
  if (walks.size() != rays_.size() || stamp.size() != dense_.size() || sensor.x < sensor_min_.x ||
      sensor.y < sensor_min_.y || sensor.x > sensor_max_.x || sensor.y > sensor_max_.y) {
    return true;
  }
  const std::uint32_t* at = stamp.data() +
                            static_cast<std::size_t>(sensor.y - dense_origin_.y) * dense_cols_ +
                            static_cast<std::size_t>(sensor.x - dense_origin_.x);
  for (std::size_t r = 0; r < rays_.size(); ++r) {
    if (walks[r] == 0) continue;
    const std::uint32_t begin = rays_[r].walk_begin;
    const std::uint32_t end =
        walks[r] == 255 ? rays_[r].walk_end : std::min(rays_[r].walk_end, begin + walks[r]);
    for (std::uint32_t k = begin; k < end; ++k) {
      if (at[deltas_[k]] >= since) return true;
    }
  }
  return false;
}

CellGrid<std::uint8_t> predict_visible(const MlsMap& map, const CellGrid<Region>& raster,
                                       const Eigen::Vector2d& sensor_xy, double floor_z,
                                       const VisibilityConfig& cfg) {
  if (!sensor_xy.allFinite()) {
    throw std::invalid_argument("predict_visible: the sensor position is not finite");
  }
  const CellIndex c = map.index_of(sensor_xy.x(), sensor_xy.y());
  const Eigen::Vector2d offset =
      (sensor_xy / map.cell_m() - Eigen::Vector2d(c.x, c.y)).cwiseMax(0.0).cwiseMin(1.0 - 1e-9);
  const VisibilityPredictor predictor(map, raster, cfg, offset);
  CellGrid<std::uint8_t> out(raster.origin, raster.cols, raster.rows, raster.cell_m, 0);
  auto ws = predictor.workspace();
  for (const std::uint32_t o : predictor.visible_from(c, floor_z, ws)) out.values[o] = 1;
  return out;
}

}  // namespace scanplan
