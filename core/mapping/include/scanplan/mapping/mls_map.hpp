#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "scanplan/geometry/cell_index.hpp"
#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

struct MlsConfig {
  double cell_m = 1.0;  // paper §3.5: 1.0 m cells
  // Points closer in height than this join one patch; a larger gap is free space the robot fits
  // into, so the ground under a canopy stays a surface of its own (paper §3.1, Fig. 2-3).
  double robot_height_m = 1.5;
  // Points farther than this from the map origin are refused: a coordinate like 1e30 is a
  // broken scan, and storing it would only grow the map without end.
  double max_coordinate_m = 1e6;
  // Beyond about 10 m the ground returns of neighbouring beams of one fan land metres apart
  // (spacing ≈ range² · step / height), leaving rings of data with unseen cells between them.
  // The beam passed over those cells without meeting anything, so insert_scan fills them with
  // the surface interpolated between the two returns, where that surface is gentle enough
  // (slope below fill_max_slope) and the returns no farther apart than fill_max_gap_m.
  bool fill_between_beams = true;
  double fill_max_gap_m = 10.0;
  double fill_max_slope = 0.25;
};

// The x-y directions a surface was measured from, in 16 sectors of 22.5° (bit b: the direction
// from a point to the scanner that measured it lay within [22.5° b, 22.5° (b + 1)) of the x
// axis). A wall is a face seen from one side: a scan from behind it meets another face, or
// nothing, of the same cell (RegistrabilityField).
using ViewSectors = std::uint16_t;
inline constexpr int kViewSectors = 16;
// The sector of direction (dx, dy); comparisons only, as it runs for every point inserted.
inline int view_sector(float dx, float dy) {
  constexpr float kTan22 = 0.41421356f, kTan67 = 2.41421356f;  // tan 22.5°, tan 67.5°
  const float ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
  // The sector within the quadrant, from the x axis.
  const int s = ay < kTan22 * ax ? 0 : ay < ax ? 1 : ay < kTan67 * ax ? 2 : 3;
  if (dy >= 0) return dx >= 0 ? s : 7 - s;
  return dx < 0 ? 8 + s : 15 - s;
}

// One surface in a cell: the heights of the points that fell on it.
struct SurfacePatch {
  float min_z = 0, max_z = 0;
  float mean_z = 0;
  float m2 = 0;  // sum of squared deviations from the mean (Welford)
  std::uint32_t count = 0;
  // Where its points were measured from (none for points inserted without their scanner).
  ViewSectors seen_from = 0;

  float variance() const { return count > 1 ? m2 / static_cast<float>(count - 1) : 0.0f; }
  float extent() const { return max_z - min_z; }  // vertical depth: walls are deep, floors thin
  void add(float z);
  void merge(const SurfacePatch& other);
};

// The surfaces of one cell, lowest first. Four fit without any allocation; a fifth surface in
// one cell (four gaps taller than the robot stacked in 1 m²) is folded into its nearest one.
struct MlsCell {
  static constexpr int kMaxPatches = 4;
  std::array<SurfacePatch, kMaxPatches> patches{};
  std::uint8_t size = 0;
  // Every height here was interpolated between two beams (MlsConfig::fill_between_beams), none
  // measured. The first measured point replaces them: interpolation across the foot of a wall
  // leaves a slope that is not there, and folded into the real ground it would make the cell
  // one deep patch instead of a floor.
  bool interpolated = false;

  bool empty() const { return size == 0; }
  const SurfacePatch* begin() const { return patches.data(); }
  const SurfacePatch* end() const { return patches.data() + size; }
  // The highest point in the cell: what a DEM keeps (paper §3.1, Fig. 2-b).
  float dem_height() const { return patches[size - 1].max_z; }
};

struct InsertStats {
  std::size_t inserted = 0;
  std::size_t rejected = 0;  // non-finite or absurdly far points
};

// A Multi-Level Surface map (Triebel, Pfaff, Burgard 2006) over an x-y grid that grows as scans
// arrive. Cells live in square tiles created on first touch, so the map has no fixed size and
// consecutive points of a scan (which are neighbours) mostly stay within one tile.
class MlsMap {
 public:
  static constexpr int kTileBits = 5;  // 32 × 32 cells a tile
  static constexpr int kTileSize = 1 << kTileBits;

  // A part of the map in whole tiles, where scans are taken out and put back (clear(), and the
  // `only` of insert_scan): a cell keeps running statistics of its heights, not the points, so
  // one scan cannot be subtracted from it.
  class Tiles {
   public:
    // The tiles under the x-y extent of `box` (map frame); an empty box adds none.
    void add(const Bounds3& box);
    bool reaches(const Bounds3& box) const;
    bool contains(std::int32_t tx, std::int32_t ty) const;
    bool empty() const { return rects_.empty(); }
    // The tiles west and east of a column chosen so that the two hold about as many tiles:
    // parts of the map to fill at once (MlsMap::adopt). The east half is empty when the tiles
    // span one column.
    std::pair<Tiles, Tiles> halves() const;

   private:
    friend class MlsMap;
    struct Rect {
      std::int32_t x0, y0, x1, y1;  // tile indices, inclusive
    };
    Tiles(double inv_cell, double max_coordinate_m)
        : inv_cell_(inv_cell), max_coordinate_m_(max_coordinate_m) {}
    std::optional<Rect> rect_of(const Bounds3& box) const;
    double inv_cell_, max_coordinate_m_;
    std::vector<Rect> rects_;
  };

  explicit MlsMap(MlsConfig config = {});

  // Points already in the map frame (after matching). Non-finite points are refused. With
  // `scanner`, the x-y position they were measured from (SurfacePatch::seen_from).
  InsertStats insert(const PointCloud& cloud);
  InsertStats insert(const std::vector<Eigen::Vector3f>& points,
                     std::optional<Eigen::Vector2d> scanner = std::nullopt);
  // A whole scan in its sensor's own frame, in the order the scanner measured it (fan by fan),
  // placed by `map_from_scan`; fills the ground between neighbouring returns of a fan (see
  // MlsConfig::fill_between_beams). `sensor_in_scan` is the laser's centre in the scan frame.
  // With `only`, cells outside those tiles are left as they are.
  InsertStats insert_scan(const PointCloud& scan, const Eigen::Isometry3d& map_from_scan,
                          const Eigen::Vector3d& sensor_in_scan, const Tiles* only = nullptr);
  // The same with the scan's points already in the map frame, as placed at `placed_at` (the
  // mission keeps them so), put where `map_from_scan` places the scan: moved on the fly, no copy
  // carried back into the scan's own frame.
  InsertStats insert_placed_scan(const PointCloud& in_map, const Eigen::Isometry3d& placed_at,
                                 const Eigen::Isometry3d& map_from_scan,
                                 const Eigen::Vector3d& sensor_in_scan,
                                 const Tiles* only = nullptr);

  // An empty part of the map to fill with Tiles::add.
  Tiles tiles() const { return Tiles(inv_cell_, config_.max_coordinate_m); }
  // Empties every cell of `tiles`. Filled again by inserting, restricted to them, each scan that
  // reaches them in the order the scans first went in, they hold what those scans would have
  // made of an empty map, cell for cell: a cell's state follows from the points that reached it,
  // in their order.
  void clear(const Tiles& tiles);
  // Takes over every tile of `part` (a map of the same configuration, filled restricted to
  // tiles this map has cleared or never had): a map filled part by part, each part by another
  // thread, as MappingPipeline::replace_scans does.
  void adopt(MlsMap&& part);

  const MlsConfig& config() const { return config_; }
  double cell_m() const { return config_.cell_m; }
  CellIndex index_of(double x, double y) const;
  Eigen::Vector2d center_of(CellIndex c) const;
  // Null when nothing was ever seen there.
  const MlsCell* cell(CellIndex c) const;
  // Inclusive bounds of all touched cells; nothing while the map is empty.
  std::optional<std::pair<CellIndex, CellIndex>> extent() const;
  std::size_t occupied_cells() const { return occupied_; }

  // Calls fn(CellIndex, const MlsCell&) for every occupied cell (in no particular order).
  template <typename Fn>
  void for_each_cell(Fn&& fn) const;

 private:
  struct Tile {
    std::array<MlsCell, kTileSize * kTileSize> cells{};
  };
  // The tile last written, so that a scan's neighbouring points look their tile up once; and
  // the tiles writes are restricted to.
  struct Cursor {
    const Tiles* only = nullptr;
    Tile* tile = nullptr;  // null: none yet, or outside `only`
    std::uint64_t key = 0;
    bool valid = false;
    // The scanner's x-y position in the map frame, when known.
    bool scanner_known = false;
    float scanner_x = 0, scanner_y = 0;
  };
  static std::uint64_t tile_key(std::int32_t tx, std::int32_t ty);
  // `placed_at`: where the points were placed in the map frame; nothing: in the scan's frame.
  template <bool kPlaced>
  InsertStats insert_fans(const PointCloud& scan, const Eigen::Isometry3d* placed_at,
                          const Eigen::Isometry3d& map_from_scan,
                          const Eigen::Vector3d& sensor_in_scan, const Tiles* only);
  void insert_point(const Eigen::Vector3f& p, Cursor& at);
  void add_to_cell(MlsCell& cell, float z, ViewSectors seen_from);
  // The cell, perhaps empty, its tile made if need be; null outside the cursor's `only`.
  MlsCell* cell_at(CellIndex c, Cursor& at);
  void enter_tile(std::int32_t tx, std::int32_t ty, Cursor& at);
  // Counts an empty cell about to be filled.
  void occupy(CellIndex c);
  void fill_between(const Eigen::Vector3f& a, const Eigen::Vector3f& b, Cursor& at);
  void recompute_extent();

  MlsConfig config_;
  float gap_;
  double inv_cell_;
  std::unordered_map<std::uint64_t, std::unique_ptr<Tile>> tiles_;
  std::size_t occupied_ = 0;
  CellIndex min_{}, max_{};
};

template <typename Fn>
void MlsMap::for_each_cell(Fn&& fn) const {
  for (const auto& [key, tile] : tiles_) {
    const std::int32_t tx = static_cast<std::int32_t>(key >> 32);
    const std::int32_t ty = static_cast<std::int32_t>(key & 0xffffffffu);
    for (int j = 0; j < kTileSize; ++j) {
      for (int i = 0; i < kTileSize; ++i) {
        const MlsCell& c = tile->cells[j * kTileSize + i];
        if (!c.empty()) fn(CellIndex{tx * kTileSize + i, ty * kTileSize + j}, c);
      }
    }
  }
}

}  // namespace scanplan
