#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/planning/scan_gain.hpp"

namespace scanplan {

// F evaluations kept from one plan to the next (issue 19). A scan changes the map, the regions
// and the anchored map only where it saw something; an evaluation whose rays walked none of
// those cells reads exactly what it read before, so its result is reused as it is: the plan
// is the one every evaluation made afresh gives, bit for bit. After a campus scan late in a
// mission most of the region is out of the new scan's reach (docs/benchmarks.md).
//
// How: at the start of each plan (begin) every cell of the predictor's dense raster gets a
// digest of what an evaluation reads there (ScanGainEvaluator::cell_digest); a cell whose digest
// differs from the previous plan's is stamped with the plan's generation. An evaluation is kept
// with how far each of its rays walked (VisibilityPredictor::Workspace::walks) and the generation
// it was made in; it still holds while no cell along those walks carries a later stamp. A change
// of anything else an evaluation depends on (ScanGainEvaluator::digest: α, the configuration,
// the highest surface in the map) forgets everything.
//
// One memo serves one sequence of plans (one robot's); plan_next_scan takes it for the length
// of a plan and plans without it when another plan holds it.
class GainMemo {
 public:
  // Keeps at most this many evaluations (each ~0.8 kB on the campus); beyond it, forgets them
  // all and starts again.
  explicit GainMemo(std::size_t max_entries = 65536) : max_entries_(max_entries) {}

  // Starts a plan against `gain`: stamps the cells that changed since the previous plan.
  void begin(const ScanGainEvaluator& gain);
  // The evaluation at `cell`, the floor at `floor_z`, when one still holds. Safe to call from
  // many threads between begin and keep.
  std::optional<ScanGain> find(const ScanGainEvaluator& gain, CellIndex cell, float floor_z) const;
  // Keeps a fresh evaluation with the walks of the workspace it was made with.
  void keep(CellIndex cell, float floor_z, const ScanGain& g, std::vector<std::uint8_t> walks);

  // Whether the latest begin forgot everything (ScanGainEvaluator::digest changed).
  bool cleared() const { return cleared_; }
  std::size_t size() const { return entries_.size(); }
  std::mutex& in_use() { return in_use_; }

 private:
  struct Entry {
    float floor_z = 0;
    std::uint32_t generation = 0;
    ScanGain gain;
    std::vector<std::uint8_t> walks;
  };
  static std::uint64_t key(CellIndex c) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.x)) << 32) |
           static_cast<std::uint32_t>(c.y);
  }

  std::size_t max_entries_;
  std::mutex in_use_;
  std::unordered_map<std::uint64_t, Entry> entries_;
  std::uint32_t generation_ = 0;
  std::uint64_t digest_ = 0;
  // Over the dense raster of the latest plan's predictor: each cell's digest and the generation
  // it last changed in.
  CellIndex origin_{0, 0};
  int cols_ = 0, rows_ = 0;
  std::vector<std::uint64_t> cell_digests_;
  std::vector<std::uint32_t> stamps_;
  bool cleared_ = false;
};

}  // namespace scanplan
