#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/geometry/scanner_model.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/region_segmentation.hpp"

namespace scanplan {

// How a scan from a candidate point B is predicted (paper §3.4: "a ray-tracing scan in 3-D
// virtual space" through the MLS map). The scanner is modelled beam by beam in elevation, as
// simulate_scan measures, so the far ground comes out in the same rings a real scan leaves;
// azimuth is sampled more coarsely, since neighbouring fans see nearly the same cells.
struct VisibilityConfig {
  // The finest azimuth step, used where rays are far apart. Nearer the sensor fewer rays
  // suffice: a ray is split in two where its neighbours would otherwise be more than
  // max_ray_spacing_m apart, so every cell is crossed by some ray and none by dozens.
  double azimuth_step_deg = 1.0;
  double max_ray_spacing_m = 1.0;
  double max_range_m = 80.0;
  double sensor_height_m = 1.0;  // laser centre above the floor B stands on
  // The vertical fan, as ScannerConfig: beams at -fov/2 + k·step, both ends included.
  double elevation_step_deg = 0.5;
  double vertical_fov_deg = 180.0;
  double min_range_m = 0.5;
  // Below the lowest surface of a cell the ground is solid: a beam that meets the side of
  // that column (a kerb, a wall's foot, the next cell of ground a few centimetres higher) ends
  // there. Unknown cells (no data in the map) are assumed to be ground at the height of the
  // last ground seen along the ray (the floor of B before any): descending beams land there
  // and the cell is predicted seen; beams above pass over it. This is the frontier assumption
  // — what has not been seen is open ground until a scan shows otherwise. The same ground is
  // assumed under a cell whose lowest surface hangs more than ground_max_jump_m above it (a
  // canopy whose ground was not seen). With unknown_as_ground off, unknown cells are empty
  // space and never predicted seen.
  bool unknown_as_ground = true;
  // A known cell carries the ground height on only when its lowest patch is this thin (a
  // floor, not a wall or a canopy) and within ground_max_jump_m of the height carried so far.
  double ground_max_extent_m = 0.3;
  double ground_max_jump_m = 1.0;
  // A standing object no more than two cells across (a post, a trunk, a bollard) fills its
  // cells in the map but is usually far thinner: it stops only the rays passing within this
  // distance of its centre, or a 16 cm lamp post would cast the shadow of a 2 m pillar.
  // Zero: every patch fills its cell.
  double thin_object_radius_m = 0.3;

  // The scanner's geometry (fan, range, mount height); the azimuth sampling stays as it is.
  static VisibilityConfig from_scanner(const ScannerConfig& scanner);
};

// Predicts which cells of a raster (the region map's grid) a scan from a cell centre would put
// data in: a 2.5-D viewshed per azimuth. Each ray walks the map's cells outward and keeps the
// set of elevation beams not yet stopped; a cell's patches stop the beams whose slopes cross
// them (so a canopy stops the rising beams and lets the ones beneath it reach the ground), and
// the cell is seen when at least one beam ends on it within range. Between consecutive returns
// of one fan the ground is filled exactly as MlsMap::insert_scan fills it (MlsConfig
// fill_between_beams, fill_max_gap_m, fill_max_slope, taken from the map), so the prediction
// covers what inserting the real scan would.
//
// Built once per map state (it copies the map into a dense raster and precomputes each
// azimuth's cell walk); `visible_from` is const and may run on many threads, each with its own
// Workspace.
class VisibilityPredictor {
 public:
  class Workspace {
   public:
    Workspace() = default;
    // How far the last prediction walked each ray of the tree (steps from the sensor, 0: not
    // traced, 255: 255 or more), what walks_reach reads back.
    const std::vector<std::uint8_t>& walks() const { return walked; }

   private:
    friend class VisibilityPredictor;
    std::vector<std::uint32_t> stamp;
    std::uint32_t epoch = 0;
    std::vector<std::uint32_t> visible;
    std::vector<std::uint8_t> walked;
  };

  // `sensor_offset` is where in its cell the sensor stands, as fractions of the cell (the
  // centre by default, which is where candidates are evaluated). The predictor answers for
  // sensors anywhere within the map's extent and the raster.
  VisibilityPredictor(const MlsMap& map, CellIndex raster_origin, int raster_cols, int raster_rows,
                      const VisibilityConfig& config,
                      const Eigen::Vector2d& sensor_offset = {0.5, 0.5});
  template <typename T>
  VisibilityPredictor(const MlsMap& map, const CellGrid<T>& raster, const VisibilityConfig& config,
                      const Eigen::Vector2d& sensor_offset = {0.5, 0.5})
      : VisibilityPredictor(map, raster.origin, raster.cols, raster.rows, config, sensor_offset) {}

  Workspace workspace() const;
  // Raster offsets (row-major, as CellGrid) of the cells a scan from `sensor_cell`, its floor
  // at `floor_z`, would put data in; each offset once. Valid until the workspace is reused.
  // Throws std::out_of_range for a sensor cell outside the area given at construction.
  const std::vector<std::uint32_t>& visible_from(CellIndex sensor_cell, double floor_z,
                                                 Workspace& ws) const;

  int beams() const { return beams_; }
  int azimuths() const { return azimuths_; }

  // What a prediction reads, for reusing one while it still holds (GainMemo). A prediction
  // reads the dense raster's cells along the walks of its rays and nothing else of the map;
  // `digest` covers the rest it depends on (the configuration, the fan, the ray tree, the
  // highest surface), `cell_digest` one cell's surfaces as the rays meet them.
  CellIndex dense_origin() const { return dense_origin_; }
  int dense_cols() const { return dense_cols_; }
  int dense_rows() const { return dense_rows_; }
  std::uint64_t digest() const;
  std::uint64_t cell_digest(std::size_t dense_offset) const;
  // Whether a walk of a prediction from `sensor` (its Workspace::walks) went through a cell
  // whose stamp (row-major over the dense raster) is `since` or later.
  bool walks_reach(CellIndex sensor, const std::vector<std::uint8_t>& walks,
                   const std::vector<std::uint32_t>& stamp, std::uint32_t since) const;

 private:
  static constexpr int kMaxBeamWords = 32;  // 2048 beams in a fan
  struct Step {
    std::int32_t dense_delta;  // offset in the dense map from the sensor's cell
    std::int16_t di, dj;       // cell offset from the sensor's cell
    float d0, d1;              // horizontal distances where the ray enters and leaves the cell
    float inv_d0, inv_d1;
  };
  // What most cells need: the lowest patch and the top. The rest of the patches lie apart
  // in `patches_`, read only for the few cells that stop a beam.
  struct DenseCell {
    float lo0 = 0, hi0 = 0, top = 0;
    std::int16_t n = 0;      // patches; 0 = unknown
    std::int16_t thin = -1;  // index into thin_centres_ when the lowest patch is a thin object
  };
  struct Trace;     // one call's constants
  struct RayState;  // what a ray carries outward and hands to the rays it splits into
  struct Tracer;    // one ray's walk through the cells
  struct Ray {
    Eigen::Vector2f dir;
    std::uint32_t walk_begin, segment_begin, walk_end;  // into steps_
  };
  // The map copied into dense_ and patches_, padded by the range around where sensors may stand.
  void build_dense(const MlsMap& map);
  // The tree of rays and their walks through the cells, from `sensor_offset` in a cell.
  void build_rays(const Eigen::Vector2d& sensor_offset);
  void walk(double azimuth, double reach_cells, const Eigen::Vector2d& sensor_offset);
  void trace(const Trace& t, int level, int ray, RayState& state, Workspace& ws) const;
  void mark(const Trace& t, const Step& s, Workspace& ws) const;

  VisibilityConfig config_;
  double cell_m_;
  bool fill_;
  float fill_max_gap_, fill_max_slope_;
  // The map copied into a dense raster padded by the maximum range on every side, so no ray
  // ever needs a bounds check or a hash look-up.
  CellIndex dense_origin_;
  int dense_cols_ = 0, dense_rows_ = 0;
  CellIndex sensor_min_, sensor_max_;  // where a sensor may stand
  std::vector<DenseCell> dense_;
  std::vector<std::array<float, 2 * MlsCell::kMaxPatches>> patches_;  // per dense cell: lo, hi…
  std::vector<Eigen::Vector2f> thin_centres_;  // metres from the dense map's corner
  Eigen::Vector2d sensor_offset_;
  void find_thin_objects();
  float max_z_ = 0;
  CellIndex raster_origin_;
  int raster_cols_, raster_rows_;
  int beams_ = 0;
  std::vector<float> slope_;  // tan of each beam's elevation
  std::vector<float> inv_slope_;
  float el0_, inv_el_step_;
  // The ray tree: at level l the rays are 2^l azimuth steps apart and cover the distances
  // where that spacing stays within max_ray_spacing_m, level 0 out to the maximum range. Each
  // ray's walk runs from the sensor to the end of its level's distances.
  int azimuths_ = 0, levels_ = 0;
  std::vector<Ray> rays_;
  std::vector<std::uint32_t> level_offset_;  // first ray of each level in rays_
  std::vector<Step> steps_;
  std::vector<std::int32_t> deltas_;  // steps_[k].dense_delta, compact for walks_reach
};

// Cells of `raster` (same geometry, 1 = seen) a scan from `sensor_xy`, standing on a floor at
// `floor_z`, would put data in. Occlusion by the map's patches; see VisibilityPredictor.
CellGrid<std::uint8_t> predict_visible(const MlsMap& map, const CellGrid<Region>& raster,
                                       const Eigen::Vector2d& sensor_xy, double floor_z,
                                       const VisibilityConfig& cfg);

}  // namespace scanplan
