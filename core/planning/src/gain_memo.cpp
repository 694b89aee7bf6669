#include "scanplan/planning/gain_memo.hpp"

#include <utility>

namespace scanplan {

void GainMemo::begin(const ScanGainEvaluator& gain) {
  const VisibilityPredictor& vp = gain.predictor();
  ++generation_;
  cleared_ = false;
  const std::uint64_t digest = gain.digest();
  if (digest != digest_ || generation_ == 0) {
    entries_.clear();
    digest_ = digest;
    cleared_ = true;
  }
  const CellIndex origin = vp.dense_origin();
  const int cols = vp.dense_cols(), rows = vp.dense_rows();
  std::vector<std::uint64_t> digests(static_cast<std::size_t>(cols) * rows);
  std::vector<std::uint32_t> stamps(digests.size(), generation_);
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const std::size_t o = static_cast<std::size_t>(j) * cols + i;
      digests[o] = gain.cell_digest(o);
      // A cell new to the raster counts as changed: no walk of an earlier plan reached it.
      const int oi = origin.x + i - origin_.x, oj = origin.y + j - origin_.y;
      if (oi < 0 || oj < 0 || oi >= cols_ || oj >= rows_) continue;
      const std::size_t old = static_cast<std::size_t>(oj) * cols_ + oi;
      if (cell_digests_[old] == digests[o]) stamps[o] = stamps_[old];
    }
  }
  origin_ = origin;
  cols_ = cols;
  rows_ = rows;
  cell_digests_ = std::move(digests);
  stamps_ = std::move(stamps);
}

std::optional<ScanGain> GainMemo::find(const ScanGainEvaluator& gain, CellIndex cell,
                                       float floor_z) const {
  const auto it = entries_.find(key(cell));
  if (it == entries_.end() || it->second.floor_z != floor_z) return std::nullopt;
  const Entry& e = it->second;
  if (e.generation != generation_ &&
      gain.predictor().walks_reach(cell, e.walks, stamps_, e.generation + 1)) {
    return std::nullopt;
  }
  return e.gain;
}

void GainMemo::keep(CellIndex cell, float floor_z, const ScanGain& g,
                    std::vector<std::uint8_t> walks) {
  if (entries_.size() >= max_entries_) entries_.clear();
  entries_[key(cell)] = Entry{floor_z, generation_, g, std::move(walks)};
}

}  // namespace scanplan
