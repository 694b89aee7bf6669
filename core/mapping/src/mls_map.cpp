#include "scanplan/mapping/mls_map.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace scanplan {

void SurfacePatch::add(float z) {
  if (count == 0) {
    min_z = max_z = mean_z = z;
    m2 = 0;
    count = 1;
    return;
  }
  ++count;
  const float delta = z - mean_z;
  mean_z += delta / static_cast<float>(count);
  m2 += delta * (z - mean_z);
  min_z = std::min(min_z, z);
  max_z = std::max(max_z, z);
}

void SurfacePatch::merge(const SurfacePatch& o) {
  if (o.count == 0) return;
  if (count == 0) {
    *this = o;
    return;
  }
  // Chan et al.'s pairwise update keeps the variance exact when two patches become one.
  const float n = static_cast<float>(count) + static_cast<float>(o.count);
  const float delta = o.mean_z - mean_z;
  mean_z += delta * static_cast<float>(o.count) / n;
  m2 += o.m2 + delta * delta * static_cast<float>(count) * static_cast<float>(o.count) / n;
  count += o.count;
  min_z = std::min(min_z, o.min_z);
  max_z = std::max(max_z, o.max_z);
  seen_from |= o.seen_from;
}

MlsMap::MlsMap(MlsConfig config)
    : config_(config),
      gap_(static_cast<float>(config.robot_height_m)),
      inv_cell_(1.0 / config.cell_m) {
  if (!(config.cell_m > 0) || !(config.robot_height_m > 0)) {
    throw std::invalid_argument("MLS cell size and robot height must be greater than zero");
  }
}

std::uint64_t MlsMap::tile_key(std::int32_t tx, std::int32_t ty) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(tx)) << 32) |
         static_cast<std::uint32_t>(ty);
}

CellIndex MlsMap::index_of(double x, double y) const {
  return {static_cast<std::int32_t>(std::floor(x * inv_cell_)),
          static_cast<std::int32_t>(std::floor(y * inv_cell_))};
}

Eigen::Vector2d MlsMap::center_of(CellIndex c) const {
  return {(c.x + 0.5) * config_.cell_m, (c.y + 0.5) * config_.cell_m};
}

const MlsCell* MlsMap::cell(CellIndex c) const {
  const auto it = tiles_.find(tile_key(c.x >> kTileBits, c.y >> kTileBits));
  if (it == tiles_.end()) return nullptr;
  const MlsCell& cell =
      it->second->cells[(c.y & (kTileSize - 1)) * kTileSize + (c.x & (kTileSize - 1))];
  return cell.empty() ? nullptr : &cell;
}

std::optional<std::pair<CellIndex, CellIndex>> MlsMap::extent() const {
  if (occupied_ == 0) return std::nullopt;
  return std::make_pair(min_, max_);
}

// The cursor moves to another tile: looked up, made if need be, unless outside its `only`.
void MlsMap::enter_tile(std::int32_t tx, std::int32_t ty, Cursor& at) {
  at.valid = true;
  at.key = tile_key(tx, ty);
  at.tile = nullptr;
  if (at.only && !at.only->contains(tx, ty)) return;
  auto& slot = tiles_[at.key];
  if (!slot) slot = std::make_unique<Tile>();
  at.tile = slot.get();
}

// Inlined, as insert_point: the per-point path of every insertion.
[[gnu::always_inline]] inline MlsCell* MlsMap::cell_at(CellIndex c, Cursor& at) {
  const std::int32_t tx = c.x >> kTileBits, ty = c.y >> kTileBits;
  if (!at.valid || tile_key(tx, ty) != at.key) enter_tile(tx, ty, at);
  if (!at.tile) return nullptr;
  return &at.tile->cells[(c.y & (kTileSize - 1)) * kTileSize + (c.x & (kTileSize - 1))];
}

[[gnu::always_inline]] inline void MlsMap::insert_point(const Eigen::Vector3f& p, Cursor& at) {
  const CellIndex index = index_of(p.x(), p.y());
  MlsCell* c = cell_at(index, at);
  if (!c) return;
  if (c->empty()) occupy(index);
  if (c->interpolated) {
    c->size = 0;
    c->interpolated = false;
  }
  const ViewSectors seen_from =
      at.scanner_known
          ? static_cast<ViewSectors>(1u << view_sector(at.scanner_x - p.x(), at.scanner_y - p.y()))
          : 0;
  add_to_cell(*c, p.z(), seen_from);
}

InsertStats MlsMap::insert(const PointCloud& cloud) {
  return insert(cloud.points);
}

InsertStats MlsMap::insert(const std::vector<Eigen::Vector3f>& points,
                           std::optional<Eigen::Vector2d> scanner) {
  InsertStats stats;
  Cursor at;
  if (scanner) {
    at.scanner_known = true;
    at.scanner_x = static_cast<float>(scanner->x());
    at.scanner_y = static_cast<float>(scanner->y());
  }
  const float limit = static_cast<float>(config_.max_coordinate_m);
  for (const Eigen::Vector3f& p : points) {
    // NaN fails every comparison, so this refuses NaN, ±inf and the absurdly far alike.
    if (!(std::abs(p.x()) < limit && std::abs(p.y()) < limit && std::abs(p.z()) < limit)) {
      ++stats.rejected;
      continue;
    }
    insert_point(p, at);
    ++stats.inserted;
  }
  return stats;
}

void MlsMap::occupy(CellIndex c) {
  if (occupied_ == 0) {
    min_ = max_ = c;
  } else {
    min_ = {std::min(min_.x, c.x), std::min(min_.y, c.y)};
    max_ = {std::max(max_.x, c.x), std::max(max_.y, c.y)};
  }
  ++occupied_;
}

InsertStats MlsMap::insert_scan(const PointCloud& scan, const Eigen::Isometry3d& map_from_scan,
                                const Eigen::Vector3d& sensor_in_scan, const Tiles* only) {
  return insert_fans<false>(scan, nullptr, map_from_scan, sensor_in_scan, only);
}

InsertStats MlsMap::insert_placed_scan(const PointCloud& in_map, const Eigen::Isometry3d& placed_at,
                                       const Eigen::Isometry3d& map_from_scan,
                                       const Eigen::Vector3d& sensor_in_scan, const Tiles* only) {
  if (placed_at.matrix() == map_from_scan.matrix()) {
    return insert_fans<true>(in_map, nullptr, map_from_scan, sensor_in_scan, only);
  }
  return insert_fans<true>(in_map, &placed_at, map_from_scan, sensor_in_scan, only);
}

// kPlaced: the points are in the map frame already (moved from `placed_at` to `map_from_scan`
// when given); which beams share a fan is still judged in the scan's own frame, where a fan is a
// vertical half-plane.
template <bool kPlaced>
InsertStats MlsMap::insert_fans(const PointCloud& scan, const Eigen::Isometry3d* placed_at,
                                const Eigen::Isometry3d& map_from_scan,
                                const Eigen::Vector3d& sensor_in_scan, const Tiles* only) {
  InsertStats stats;
  Cursor at;
  at.only = only;
  const Eigen::Vector3d scanner = map_from_scan * sensor_in_scan;
  at.scanner_known = true;
  at.scanner_x = static_cast<float>(scanner.x());
  at.scanner_y = static_cast<float>(scanner.y());
  const Eigen::Isometry3f T = map_from_scan.cast<float>();
  const Eigen::Isometry3f lag =
      placed_at ? Eigen::Isometry3f((map_from_scan * placed_at->inverse()).cast<float>())
                : Eigen::Isometry3f::Identity();
  const Eigen::Isometry3f T_inverse = map_from_scan.inverse().cast<float>();
  const Eigen::Vector3f sensor = sensor_in_scan.cast<float>();
  const float limit = static_cast<float>(config_.max_coordinate_m);
  // Neighbouring beams of one fan share their azimuth; both must look down at the ground, by
  // more than a level beam carried into the map frame and back can (its last bit must not
  // decide).
  struct Beam {
    Eigen::Vector3f d;
    float horizontal;
    bool usable;
  };
  // `point` as given, `q` where it goes in the map.
  const auto beam_of = [&](const Eigen::Vector3f& point, const Eigen::Vector3f& q) {
    const Eigen::Vector3f p = kPlaced ? Eigen::Vector3f(T_inverse * q) : point;
    Beam b{p - sensor, 0, false};
    b.horizontal = std::sqrt(b.d.x() * b.d.x() + b.d.y() * b.d.y());  // never near overflow
    b.usable = b.d.z() < -1e-3f * b.horizontal && b.horizontal > 0.3f;
    return b;
  };
  // The previous point, when it was not refused; its beam only once needed (see below).
  const Eigen::Vector3f* prev = nullptr;
  std::optional<Beam> prev_beam;
  Eigen::Vector3f prev_map = Eigen::Vector3f::Zero();
  std::uint64_t prev_key = 0;
  bool prev_outside = false;
  for (const Eigen::Vector3f& point : scan.points) {
    const Eigen::Vector3f q =
        kPlaced ? (placed_at ? Eigen::Vector3f(lag * point) : point) : Eigen::Vector3f(T * point);
    if (!(std::abs(q.x()) < limit && std::abs(q.y()) < limit && std::abs(q.z()) < limit)) {
      ++stats.rejected;
      prev = nullptr;
      continue;
    }
    insert_point(q, at);  // leaves the cursor on q's tile
    ++stats.inserted;
    if (!config_.fill_between_beams) continue;
    const bool outside = at.tile == nullptr;
    const std::uint64_t key = at.key;
    // Two points in one tile outside `only` fill nothing (fill_between stays within the pair's
    // box): restricted, most of a scan passes without its beams worked out.
    if (prev && outside && prev_outside && key == prev_key) {
      prev_beam.reset();
    } else {
      const Beam beam = beam_of(point, q);
      if (prev && beam.usable) {
        if (!prev_beam) prev_beam = beam_of(*prev, prev_map);
        const Beam& b = *prev_beam;
        const float cos_az =
            (beam.d.x() * b.d.x() + beam.d.y() * b.d.y()) / (beam.horizontal * b.horizontal);
        // Same fan: azimuths within about a quarter degree.
        if (b.usable && cos_az > 0.99999f) fill_between(prev_map, q, at);
      }
      prev_beam = beam;
    }
    prev = &point;
    prev_map = q;
    prev_key = key;
    prev_outside = outside;
  }
  return stats;
}

void MlsMap::fill_between(const Eigen::Vector3f& a, const Eigen::Vector3f& b, Cursor& at) {
  const Eigen::Vector2f delta = b.head<2>() - a.head<2>();
  const float length = delta.norm();
  if (length < config_.cell_m || length > config_.fill_max_gap_m) return;
  if (std::abs(b.z() - a.z()) > config_.fill_max_slope * length) return;
  if (at.only) {
    Bounds3 segment;
    segment.extend(a);
    segment.extend(b);
    if (!at.only->reaches(segment)) return;  // nothing it crosses may be written
  }
  // Half-cell steps visit every cell the segment crosses.
  const int steps = static_cast<int>(std::ceil(length / (0.5 * config_.cell_m)));
  for (int k = 1; k < steps; ++k) {
    Eigen::Vector3f p = a + (b - a) * (static_cast<float>(k) / static_cast<float>(steps));
    // Within the pair's box to the last bit, so that a pair in one tile fills only that tile.
    p.head<2>() = p.head<2>().cwiseMax(a.head<2>().cwiseMin(b.head<2>()));
    p.head<2>() = p.head<2>().cwiseMin(a.head<2>().cwiseMax(b.head<2>()));
    const CellIndex c = index_of(p.x(), p.y());
    // Only cells the laser saw nothing in: measured surfaces keep their own statistics.
    MlsCell* filled = cell_at(c, at);
    if (!filled || !filled->empty()) continue;
    occupy(c);
    add_to_cell(*filled, p.z(), 0);
    filled->interpolated = true;
  }
}

std::optional<MlsMap::Tiles::Rect> MlsMap::Tiles::rect_of(const Bounds3& box) const {
  if (!box.valid()) return std::nullopt;
  // Beyond max_coordinate_m nothing is stored; one cell of margin for rounding.
  const auto tile = [&](float v, double margin) {
    const double clamped =
        std::clamp(static_cast<double>(v) + margin, -max_coordinate_m_, max_coordinate_m_);
    return static_cast<std::int32_t>(std::floor(clamped * inv_cell_)) >> kTileBits;
  };
  const double cell = 1.0 / inv_cell_;
  return Rect{tile(box.min.x(), -cell), tile(box.min.y(), -cell), tile(box.max.x(), cell),
              tile(box.max.y(), cell)};
}

void MlsMap::Tiles::add(const Bounds3& box) {
  if (const auto r = rect_of(box)) rects_.push_back(*r);
}

bool MlsMap::Tiles::contains(std::int32_t tx, std::int32_t ty) const {
  return std::any_of(rects_.begin(), rects_.end(), [&](const Rect& r) {
    return tx >= r.x0 && tx <= r.x1 && ty >= r.y0 && ty <= r.y1;
  });
}

bool MlsMap::Tiles::reaches(const Bounds3& box) const {
  const auto b = rect_of(box);
  if (!b) return false;
  return std::any_of(rects_.begin(), rects_.end(), [&](const Rect& r) {
    return b->x0 <= r.x1 && r.x0 <= b->x1 && b->y0 <= r.y1 && r.y0 <= b->y1;
  });
}

std::pair<MlsMap::Tiles, MlsMap::Tiles> MlsMap::Tiles::halves() const {
  std::pair<Tiles, Tiles> out{Tiles(inv_cell_, max_coordinate_m_),
                              Tiles(inv_cell_, max_coordinate_m_)};
  if (rects_.empty()) return out;
  // The column where the rectangles' tiles (overlaps counted twice: near enough) reach half.
  std::int64_t total = 0;
  std::int32_t lo = rects_.front().x0, hi = rects_.front().x1;
  for (const Rect& r : rects_) {
    total += static_cast<std::int64_t>(r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1);
    lo = std::min(lo, r.x0);
    hi = std::max(hi, r.x1);
  }
  std::int32_t split = hi + 1;
  std::int64_t west = 0;
  for (std::int32_t x = lo; x <= hi; ++x) {
    if (2 * west >= total) {
      split = x;
      break;
    }
    for (const Rect& r : rects_) west += (x >= r.x0 && x <= r.x1) ? r.y1 - r.y0 + 1 : 0;
  }
  for (const Rect& r : rects_) {
    if (r.x0 < split) out.first.rects_.push_back({r.x0, r.y0, std::min(r.x1, split - 1), r.y1});
    if (r.x1 >= split) out.second.rects_.push_back({std::max(r.x0, split), r.y0, r.x1, r.y1});
  }
  return out;
}

void MlsMap::adopt(MlsMap&& part) {
  if (part.config_.cell_m != config_.cell_m || part.gap_ != gap_) {
    throw std::invalid_argument("MlsMap::adopt: the part has another cell size or robot height");
  }
  for (auto& [key, tile] : part.tiles_) tiles_[key] = std::move(tile);
  occupied_ += part.occupied_;
  part.tiles_.clear();
  part.occupied_ = 0;
  recompute_extent();
}

void MlsMap::clear(const Tiles& tiles) {
  for (auto it = tiles_.begin(); it != tiles_.end();) {
    const std::int32_t tx = static_cast<std::int32_t>(it->first >> 32);
    const std::int32_t ty = static_cast<std::int32_t>(it->first & 0xffffffffu);
    if (!tiles.contains(tx, ty)) {
      ++it;
      continue;
    }
    for (const MlsCell& c : it->second->cells) occupied_ -= c.empty() ? 0 : 1;
    it = tiles_.erase(it);
  }
  recompute_extent();
}

void MlsMap::recompute_extent() {
  bool any = false;
  for_each_cell([&](CellIndex c, const MlsCell&) {
    if (!any) {
      min_ = max_ = c;
      any = true;
      return;
    }
    min_ = {std::min(min_.x, c.x), std::min(min_.y, c.y)};
    max_ = {std::max(max_.x, c.x), std::max(max_.y, c.y)};
  });
}

void MlsMap::add_to_cell(MlsCell& cell, float z, ViewSectors seen_from) {
  auto& ps = cell.patches;
  int n = cell.size;
  const auto erase = [&](int k) {
    for (int i = k; i + 1 < n; ++i) ps[i] = ps[i + 1];
    --n;
  };
  for (int k = 0; k < n; ++k) {
    if (z < ps[k].min_z - gap_ || z > ps[k].max_z + gap_) continue;
    ps[k].add(z);
    ps[k].seen_from |= seen_from;
    // Growing this patch may have closed the gap to a neighbour: the two are one surface now.
    if (k + 1 < n && ps[k + 1].min_z - ps[k].max_z <= gap_) {
      ps[k].merge(ps[k + 1]);
      erase(k + 1);
    }
    if (k > 0 && ps[k].min_z - ps[k - 1].max_z <= gap_) {
      ps[k - 1].merge(ps[k]);
      erase(k);
    }
    cell.size = static_cast<std::uint8_t>(n);
    return;
  }
  int at = 0;
  while (at < n && ps[at].min_z < z) ++at;
  if (n == MlsCell::kMaxPatches) {
    // No room for another surface: fold the point into the nearer neighbouring patch.
    const int below = at - 1, above = at < n ? at : -1;
    const int k =
        (above < 0 || (below >= 0 && z - ps[below].max_z < ps[above].min_z - z)) ? below : above;
    ps[k].add(z);
    ps[k].seen_from |= seen_from;
    return;
  }
  for (int i = n; i > at; --i) ps[i] = ps[i - 1];
  ps[at] = SurfacePatch{};
  ps[at].add(z);
  ps[at].seen_from = seen_from;
  cell.size = static_cast<std::uint8_t>(n + 1);
}

}  // namespace scanplan
