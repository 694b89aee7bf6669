#include "scanplan/core/visibility.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fast_atan.hpp"
#include "scanplan/core/pose.hpp"

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
  beams_ = static_cast<int>(std::floor(config.vertical_fov_deg / config.elevation_step_deg + 1e-9)) + 1;
  el0_ = static_cast<float>(deg2rad(-config.vertical_fov_deg / 2));
  inv_el_step_ = static_cast<float>(1.0 / deg2rad(config.elevation_step_deg));
  slope_.resize(static_cast<std::size_t>(beams_));
  inv_slope_.resize(static_cast<std::size_t>(beams_));
  for (int k = 0; k < beams_; ++k) {
    const auto u = static_cast<std::size_t>(k);
    slope_[u] = static_cast<float>(std::tan(deg2rad(-config.vertical_fov_deg / 2 + k * config.elevation_step_deg)));
    inv_slope_[u] = 1.0f / slope_[u];
  }

  // Sensors may stand anywhere over the map or the raster.
  sensor_min_ = raster_origin;
  sensor_max_ = {raster_origin.x + raster_cols - 1, raster_origin.y + raster_rows - 1};
  if (const auto extent = map.extent()) {
    sensor_min_ = {std::min(sensor_min_.x, extent->first.x), std::min(sensor_min_.y, extent->first.y)};
    sensor_max_ = {std::max(sensor_max_.x, extent->second.x), std::max(sensor_max_.y, extent->second.y)};
  }
  const int pad = static_cast<int>(std::ceil(config.max_range_m / cell_m_)) + 2;
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
    d.n = cell.size;
    d.lo0 = cell.patches[0].min_z;
    d.hi0 = cell.patches[0].max_z;
    d.top = cell.dem_height();
    for (int k = 0; k < cell.size; ++k) {
      patches_[o][2 * k] = cell.patches[k].min_z;
      patches_[o][2 * k + 1] = cell.patches[k].max_z;
    }
    max_z_ = std::max(max_z_, d.top);
  });

  // Each azimuth's walk through the cells (Amanatides & Woo), from the sensor's place in its
  // cell out to the maximum range. Every sensor stands at the same place in its cell, so one
  // table serves every candidate.
  const int n_az = std::max(1, static_cast<int>(std::lround(360.0 / config.azimuth_step_deg)));
  const double reach = config.max_range_m / cell_m_;  // in cells
  ray_begin_.reserve(static_cast<std::size_t>(n_az) + 1);
  for (int a = 0; a < n_az; ++a) {
    ray_begin_.push_back(static_cast<std::uint32_t>(steps_.size()));
    const double az = 2 * M_PI * a / n_az;
    const double cx = std::cos(az), cy = std::sin(az);
    const double inf = std::numeric_limits<double>::infinity();
    const int sx = cx > 0 ? 1 : -1, sy = cy > 0 ? 1 : -1;
    double t_max_x = cx > 1e-12 ? (1 - sensor_offset.x()) / cx
                     : cx < -1e-12 ? sensor_offset.x() / -cx
                                   : inf;
    double t_max_y = cy > 1e-12 ? (1 - sensor_offset.y()) / cy
                     : cy < -1e-12 ? sensor_offset.y() / -cy
                                   : inf;
    const double dt_x = std::abs(cx) > 1e-12 ? 1 / std::abs(cx) : inf;
    const double dt_y = std::abs(cy) > 1e-12 ? 1 / std::abs(cy) : inf;
    int i = 0, j = 0;
    double t = 0;
    while (t < reach) {
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
  ray_begin_.push_back(static_cast<std::uint32_t>(steps_.size()));

  // The ray tree. Rays 2^l steps apart reach max_ray_spacing_m apart at `reach_l`; level l
  // covers from reach_{l+1} to reach_l, the finest level everything beyond. Levels stop where
  // the azimuths no longer halve or a level would cover less than two cells.
  const double step_rad = 2 * M_PI / n_az;
  const auto reach_at = [&](int l) { return config.max_ray_spacing_m / (step_rad * (1 << l)); };
  levels_ = 0;
  while (levels_ < 6 && n_az % (2 << levels_) == 0 && reach_at(levels_ + 1) >= 2 * cell_m_) ++levels_;
  level_begin_.assign(static_cast<std::size_t>(levels_ + 1) * n_az, 0);
  for (int l = 0; l <= levels_; ++l) {
    const double from = l == levels_ ? 0.0 : reach_at(l + 1);
    for (int a = 0; a < n_az; ++a) {
      std::uint32_t k = ray_begin_[static_cast<std::size_t>(a)];
      while (k < ray_begin_[static_cast<std::size_t>(a) + 1] && steps_[k].d0 < from) ++k;
      level_begin_[static_cast<std::size_t>(l) * n_az + a] = k;
    }
  }
}

VisibilityPredictor::Workspace VisibilityPredictor::workspace() const {
  Workspace ws;
  ws.stamp.assign(static_cast<std::size_t>(raster_cols_) * raster_rows_, 0);
  return ws;
}

struct VisibilityPredictor::Trace {
  float sz, floor, ceiling, min_r2, max_r2, ground_extent, ground_jump, min_fill, min_clip;
  std::size_t base;  // the sensor's cell in the dense map
  std::int64_t i0, j0;  // the sensor's cell in the raster
};

struct VisibilityPredictor::RayState {
  std::uint64_t free[kMaxBeamWords];  // beams not yet stopped
  int k_min, k_max;  // the lowest and highest of them
  float ground;      // the ground height carried along the ray
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

void VisibilityPredictor::trace(const Trace& t, int a, int level, RayState& st, Workspace& ws) const {
  const int n_az = azimuths();
  const float* slope = slope_.data();
  const float* inv_slope = inv_slope_.data();
  const float sz = t.sz;
  const Step* walk = steps_.data() + ray_begin_[static_cast<std::size_t>(a)];
  const Step* begin = steps_.data() + level_begin_[static_cast<std::size_t>(level) * n_az + a];
  const Step* end = steps_.data() + (level == 0 ? ray_begin_[static_cast<std::size_t>(a) + 1]
                                                : level_begin_[static_cast<std::size_t>(level - 1) * n_az + a]);

  // Where beam k, known to cross the patch [lo, hi] of the cell entered at d0, first meets it.
  const auto landing = [&](int k, float d0, float lo, float hi, float& d, float& z) {
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
  };
  const auto in_range = [&](float d, float z) {
    const float r2 = d * d + (z - sz) * (z - sz);
    return r2 >= t.min_r2 && r2 <= t.max_r2;
  };
  // insert_scan's rule for filling between two neighbouring returns of a fan: both below the
  // laser and off its axis, no closer than a cell and no farther than fill_max_gap_m, gently
  // sloped. Returns come here in distance order, which for descending beams is beam order.
  const auto chain = [&](const Step* s, float d0, float z0, float d1, float z1) {
    const bool usable = z0 < sz && d0 > 0.3f;
    if (fill_ && st.have_last && st.last_usable && usable && d0 > st.last_d) {
      const float length = d0 - st.last_d;
      if (length >= t.min_fill && length <= fill_max_gap_ && std::abs(z0 - st.last_z) <= fill_max_slope_ * length) {
        for (const Step* p = s - 1; p >= walk && p->d0 >= st.last_d; --p) {
          // A corner the walk only clips is usually missed by the fill's half-cell samples.
          if (p->d1 - p->d0 >= t.min_clip) mark(t, *p, ws);
        }
      }
    }
    st.have_last = true;
    st.last_usable = z1 < sz && d1 > 0.3f;
    st.last_d = d1;
    st.last_z = z1;
  };

  for (const Step* s = begin; s != end; ++s) {
    // Every beam still free passes above the highest surface anywhere: nothing more to see.
    if (slope[st.k_min] > 0 && slope[st.k_min] * s->d0 > t.ceiling) {
      st.done = true;
      return;
    }
    const std::size_t at = t.base + static_cast<std::ptrdiff_t>(s->dense_delta);
    const DenseCell& cell = dense_[at];
    // Below the lowest surface of a cell the ground is solid (the measured top of a cell is a
    // few centimetres off its neighbour's, and a beam passing under it would slip beneath the
    // ground), unless that lowest one hangs well above the ground carried along the ray: then
    // it is a canopy or an overhang whose ground was not seen, assumed as for unknown cells.
    const bool hanging = cell.n > 0 && cell.lo0 > st.ground + t.ground_jump;
    const bool assume = cell.n == 0 || hanging;
    if (assume && !config_.unknown_as_ground && cell.n == 0) continue;
    if (!assume && cell.hi0 - cell.lo0 <= t.ground_extent && std::abs(cell.hi0 - st.ground) <= t.ground_jump) {
      st.ground = cell.hi0;
    }
    // Most cells lie wholly below the lowest free beam (ground already passed over).
    const float r_top = (cell.n == 0 ? st.ground : cell.top) - sz;
    if ((r_top > 0 ? r_top * s->inv_d0 : r_top * s->inv_d1) < slope[st.k_min]) continue;
    // The surfaces that stop beams here.
    float lo_hi[2 * (MlsCell::kMaxPatches + 1)];
    int n = 0;
    if (assume && config_.unknown_as_ground) {
      lo_hi[0] = -kSolid;
      lo_hi[1] = st.ground;
      n = 1;
    }
    for (int p = 0; p < cell.n; ++p) {
      lo_hi[2 * n] = patches_[at][2 * p];
      lo_hi[2 * n + 1] = patches_[at][2 * p + 1];
      ++n;
    }
    if (!hanging) lo_hi[0] = -kSolid;
    bool seen = false, stopped = false;
    for (int p = 0; p < n; ++p) {
      const float lo = lo_hi[2 * p], hi = lo_hi[2 * p + 1];
      // The beams crossing the box [d0, d1] × [lo, hi]: slopes between its extreme corners.
      const float rlo = lo - sz, rhi = hi - sz;
      const float t_lo = rlo < 0 ? rlo * s->inv_d0 : rlo * s->inv_d1;
      const float t_hi = rhi > 0 ? rhi * s->inv_d0 : rhi * s->inv_d1;
      if (t_hi < slope[st.k_min] || t_lo > slope[st.k_max]) continue;
      // The free beams with t_lo <= slope <= t_hi. Ground takes the lowest free beam and a few
      // above it, found by walking the slope table; atan only for tall spans.
      int k0 = st.k_min;
      if (t_lo > slope[k0]) {
        k0 = std::max(st.k_min, static_cast<int>(std::ceil((fast_atan(t_lo) - el0_) * inv_el_step_)));
        while (k0 > st.k_min && slope[k0 - 1] >= t_lo) --k0;
        while (k0 <= st.k_max && slope[k0] < t_lo) ++k0;
        if (k0 > st.k_max) continue;
      }
      int k1 = st.k_max;
      if (t_hi < slope[k1]) {
        k1 = k0 - 1;
        int walked = 0;
        while (walked < 8 && slope[k1 + 1] <= t_hi) {
          ++k1;
          ++walked;
        }
        if (walked == 8) {
          k1 = std::min(st.k_max, static_cast<int>(std::floor((fast_atan(t_hi) - el0_) * inv_el_step_)));
          while (k1 < st.k_max && slope[k1 + 1] <= t_hi) ++k1;
          while (k1 >= k0 && slope[k1] > t_hi) --k1;
        }
      }
      if (k0 > k1) continue;
      const int w0 = k0 >> 6, w1 = k1 >> 6;
      for (int w = w0; w <= w1; ++w) {
        std::uint64_t m = st.free[w];
        if (w == w0) m &= ~0ull << (k0 & 63);
        if (w == w1 && (k1 & 63) != 63) m &= (1ull << ((k1 & 63) + 1)) - 1;
        if (!m) continue;
        st.free[w] &= ~m;
        stopped = true;
        // Each run of still-free beams ends here; the beams it stops leave no return beyond.
        while (m) {
          const int b = std::countr_zero(m);
          const std::uint64_t shifted = m >> b;
          const int len = ~shifted == 0 ? 64 - b : std::countr_zero(~shifted);
          const int kf = 64 * w + b, kl = kf + len - 1;
          m = b + len >= 64 ? 0 : m & (~0ull << (b + len));
          float df, zf, dl, zl;
          landing(kf, s->d0, lo, hi, df, zf);
          landing(kl, s->d0, lo, hi, dl, zl);
          if (!in_range(df, zf) && !in_range(dl, zl)) continue;  // no return: no point
          seen = true;
          if (zf < sz) chain(s, df, zf, dl, zl);
        }
      }
    }
    if (seen) mark(t, *s, ws);
    if (!stopped) continue;
    const auto is_free = [&](int k) { return (st.free[k >> 6] >> (k & 63)) & 1; };
    if (!is_free(st.k_min)) {
      int w = st.k_min >> 6;
      const int words = (beams_ + 63) >> 6;
      while (w < words && st.free[w] == 0) ++w;
      if (w == words) {  // every beam has ended
        st.done = true;
        return;
      }
      st.k_min = 64 * w + std::countr_zero(st.free[w]);
    }
    if (!is_free(st.k_max)) {
      int w = st.k_max >> 6;
      while (st.free[w] == 0) --w;
      st.k_max = 64 * w + 63 - std::countl_zero(st.free[w]);
    }
  }
  if (level == 0) return;
  // Split: the ray goes on at its azimuth, and a new one starts half-way to its neighbour
  // with everything this one has seen so far.
  RayState other = st;
  trace(t, a, level - 1, st, ws);
  trace(t, a + (1 << (level - 1)), level - 1, other, ws);
}

const std::vector<std::uint32_t>& VisibilityPredictor::visible_from(CellIndex sensor, double floor_z,
                                                                    Workspace& ws) const {
  if (sensor.x < sensor_min_.x || sensor.y < sensor_min_.y || sensor.x > sensor_max_.x ||
      sensor.y > sensor_max_.y) {
    throw std::out_of_range("visibility: sensor cell (" + std::to_string(sensor.x) + ", " +
                            std::to_string(sensor.y) +
                            ") is outside the map and raster the predictor was built for");
  }
  if (!std::isfinite(floor_z)) throw std::invalid_argument("visibility: floor height is not finite");
  if (ws.stamp.size() != static_cast<std::size_t>(raster_cols_) * raster_rows_) ws = workspace();
  if (++ws.epoch == 0) {
    std::fill(ws.stamp.begin(), ws.stamp.end(), 0);
    ws.epoch = 1;
  }
  ws.visible.clear();

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

  RayState start;
  const int words = (beams_ + 63) >> 6;
  std::fill(std::begin(start.free), std::end(start.free), 0ull);
  for (int w = 0; w < words; ++w) start.free[w] = ~0ull;
  if (beams_ % 64) start.free[words - 1] = (1ull << (beams_ % 64)) - 1;
  start.k_min = 0;
  start.k_max = beams_ - 1;
  start.ground = t.floor;
  const int n_az = azimuths();
  for (int a = 0; a < n_az; a += 1 << levels_) {
    RayState st = start;
    trace(t, a, levels_, st, ws);
  }
  return ws.visible;
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
