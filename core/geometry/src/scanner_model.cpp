#include "scanplan/geometry/scanner_model.hpp"

#include <cmath>

namespace scanplan {

int ScannerConfig::vertical_samples() const {
  // A closed fan: both ends are measured, so 180° at 0.5° gives 361 beams.
  return static_cast<int>(std::floor(vertical_fov_deg / vertical_step_deg + 1e-9)) + 1;
}

int ScannerConfig::rotation_samples() const {
  // The stage's 360° wraps: the last step would repeat the first.
  const int n = static_cast<int>(std::floor(rotation_deg / rotation_step_deg + 1e-9));
  return rotation_deg >= 360.0 - 1e-9 ? n : n + 1;
}

}  // namespace scanplan
