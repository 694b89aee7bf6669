#include "scanplan/mapping/mls_map.hpp"

#include <algorithm>
#include <cmath>
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

InsertStats MlsMap::insert(const PointCloud& cloud) {
  return insert(cloud.points);
}

InsertStats MlsMap::insert(const std::vector<Eigen::Vector3f>& points) {
  InsertStats stats;
  Tile* cached = nullptr;
  std::uint64_t cached_key = 0;
  const float limit = static_cast<float>(config_.max_coordinate_m);
  for (const Eigen::Vector3f& p : points) {
    // NaN fails every comparison, so this refuses NaN, ±inf and the absurdly far alike.
    if (!(std::abs(p.x()) < limit && std::abs(p.y()) < limit && std::abs(p.z()) < limit)) {
      ++stats.rejected;
      continue;
    }
    insert_point(p, cached, cached_key);
    ++stats.inserted;
  }
  return stats;
}

void MlsMap::insert_point(const Eigen::Vector3f& p, Tile*& cached, std::uint64_t& cached_key) {
  MlsCell& c = touch(index_of(p.x(), p.y()), cached, cached_key);
  if (c.interpolated) {
    c.size = 0;
    c.interpolated = false;
  }
  add_to_cell(c, p.z());
}

MlsCell& MlsMap::touch(CellIndex c, Tile*& cached, std::uint64_t& cached_key) {
  const std::uint64_t key = tile_key(c.x >> kTileBits, c.y >> kTileBits);
  if (!cached || key != cached_key) {
    auto& slot = tiles_[key];
    if (!slot) slot = std::make_unique<Tile>();
    cached = slot.get();
    cached_key = key;
  }
  MlsCell& cell = cached->cells[(c.y & (kTileSize - 1)) * kTileSize + (c.x & (kTileSize - 1))];
  if (cell.empty()) {
    if (occupied_ == 0) {
      min_ = max_ = c;
    } else {
      min_ = {std::min(min_.x, c.x), std::min(min_.y, c.y)};
      max_ = {std::max(max_.x, c.x), std::max(max_.y, c.y)};
    }
    ++occupied_;
  }
  return cell;
}

InsertStats MlsMap::insert_scan(const PointCloud& scan, const Eigen::Isometry3d& map_from_scan,
                                const Eigen::Vector3d& sensor_in_scan) {
  InsertStats stats;
  Tile* cached = nullptr;
  std::uint64_t cached_key = 0;
  const Eigen::Isometry3f T = map_from_scan.cast<float>();
  const Eigen::Vector3f sensor = sensor_in_scan.cast<float>();
  const float limit = static_cast<float>(config_.max_coordinate_m);
  bool have_prev = false;
  Eigen::Vector3f prev_map = Eigen::Vector3f::Zero(), prev_dir = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& p : scan.points) {
    const Eigen::Vector3f q = T * p;
    if (!(std::abs(q.x()) < limit && std::abs(q.y()) < limit && std::abs(q.z()) < limit)) {
      ++stats.rejected;
      have_prev = false;
      continue;
    }
    insert_point(q, cached, cached_key);
    ++stats.inserted;
    if (!config_.fill_between_beams) continue;
    // Neighbouring beams of one fan share their azimuth; both must look down at the ground.
    const Eigen::Vector3f d = p - sensor;
    const float horizontal = std::hypot(d.x(), d.y());
    const bool usable = d.z() < 0 && horizontal > 0.3f;
    if (usable && have_prev) {
      const float cos_az = (d.x() * prev_dir.x() + d.y() * prev_dir.y()) /
                           (horizontal * std::hypot(prev_dir.x(), prev_dir.y()));
      // Same fan: azimuths within about a quarter degree.
      if (cos_az > 0.99999f) fill_between(prev_map, q, cached, cached_key);
    }
    have_prev = usable;
    prev_map = q;
    prev_dir = d;
  }
  return stats;
}

void MlsMap::fill_between(const Eigen::Vector3f& a, const Eigen::Vector3f& b, Tile*& cached,
                          std::uint64_t& cached_key) {
  const Eigen::Vector2f delta = b.head<2>() - a.head<2>();
  const float length = delta.norm();
  if (length < config_.cell_m || length > config_.fill_max_gap_m) return;
  if (std::abs(b.z() - a.z()) > config_.fill_max_slope * length) return;
  // Half-cell steps visit every cell the segment crosses.
  const int steps = static_cast<int>(std::ceil(length / (0.5 * config_.cell_m)));
  for (int k = 1; k < steps; ++k) {
    const Eigen::Vector3f p = a + (b - a) * (static_cast<float>(k) / static_cast<float>(steps));
    const CellIndex c = index_of(p.x(), p.y());
    // Only cells the laser saw nothing in: measured surfaces keep their own statistics.
    const MlsCell* existing = cell(c);
    if (existing) continue;
    MlsCell& filled = touch(c, cached, cached_key);
    add_to_cell(filled, p.z());
    filled.interpolated = true;
  }
}

void MlsMap::add_to_cell(MlsCell& cell, float z) {
  auto& ps = cell.patches;
  int n = cell.size;
  const auto erase = [&](int k) {
    for (int i = k; i + 1 < n; ++i) ps[i] = ps[i + 1];
    --n;
  };
  for (int k = 0; k < n; ++k) {
    if (z < ps[k].min_z - gap_ || z > ps[k].max_z + gap_) continue;
    ps[k].add(z);
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
    return;
  }
  for (int i = n; i > at; --i) ps[i] = ps[i - 1];
  ps[at] = SurfacePatch{};
  ps[at].add(z);
  cell.size = static_cast<std::uint8_t>(n + 1);
}

}  // namespace scanplan
