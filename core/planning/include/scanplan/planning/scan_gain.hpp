#pragma once

#include <optional>
#include "scanplan/mapping/mls_map.hpp"

#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/planning/registrability.hpp"
#include "scanplan/planning/visibility.hpp"

namespace scanplan {

// The terms of the paper's evaluation function (§3.4, Eq. 1) for one candidate B:
//   F = α · area((U ∩ C_B) ∪ (U ∩ M_B)) + (1 − α) · area(M_A ∩ C_B)
// where C_B are the cells a scan from B is predicted to see within completed_radius_m of B
// and M_B those it sees farther out; U and M_A are the current unscanned and low-resolution
// regions. (U ∩ C_B) ∪ (U ∩ M_B) is simply U ∩ (seen from B).
struct ScanGain {
  double f = 0;
  double unscanned_m2 = 0;       // area((U∩C_B) ∪ (U∩M_B))
  double low_resolution_m2 = 0;  // area(M_A∩C_B)
  // area((U∪M_A)∩C_B): what the scan would bring into C. Not a term of F; the exhaustive
  // policy breaks near-ties in F with it (PlannerConfig::completion_weight).
  double completed_m2 = 0;
  // area((C_A∪M_A) seen from B): what a scan from B is predicted to see of the map so far, the
  // overlap scan matching will have to go on (issue 15). Not a term of F.
  double overlap_m2 = 0;
  // Whether the matcher is forecast to place the scan (with an anchored map to forecast on).
  // Not a term of F: the policies scale F by its factor.
  std::optional<Registrability> registrability;
};

// F as the policies rank it: scaled down where the matcher is forecast to fail.
inline double registrable_f(const ScanGain& g) {
  return g.registrability ? g.f * g.registrability->factor : g.f;
}

// Evaluates Eq. 1 at cells of the map against one region segmentation. Cheap to call many
// times: the visibility predictor is built once. Thread-safe with one workspace per thread.
class ScanGainEvaluator {
 public:
  // `alpha` is the paper's weight α (§3.4), in [0, 1]; throws std::invalid_argument otherwise.
  // `regions` (and `registrability`, when given: on the regions' grid) must outlive the
  // evaluator; the map is copied.
  ScanGainEvaluator(const MlsMap& map, const RegionMap& regions, double alpha,
                    const RegionConfig& region_config, const VisibilityConfig& visibility,
                    const RegistrabilityField* registrability = nullptr);

  VisibilityPredictor::Workspace workspace() const { return predictor_.workspace(); }
  // F at the centre of cell `b`, the robot standing on a floor at `floor_z`.
  ScanGain at(CellIndex b, double floor_z, VisibilityPredictor::Workspace& ws) const;
  ScanGain at(CellIndex b, double floor_z) const;

  double alpha() const { return alpha_; }
  // What an evaluation reads, for reusing one while it still holds (GainMemo): `digest` all but
  // the cells (α, the completed radius, the predictor's and the forecast's own), `cell_digest`
  // one cell of the predictor's dense raster with its region and what the anchored map holds
  // there. An evaluation reads only the cells its rays walked (VisibilityPredictor::walks_reach).
  std::uint64_t digest() const;
  std::uint64_t cell_digest(std::size_t dense_offset) const;
  const VisibilityPredictor& predictor() const { return predictor_; }

 private:
  const RegionMap& regions_;
  const RegistrabilityField* registrability_;
  double alpha_;
  double completed_radius_cells2_;
  VisibilityPredictor predictor_;
};

}  // namespace scanplan
