#pragma once

#include <cmath>

namespace scanplan {

// atan to within 1e-5 rad (Abramowitz & Stegun 4.4.49-style minimax polynomial): the viewshed
// turns a few slopes per cell into beam indices, and std::atan was a third of its time. The
// error is a thousandth of the scanner's 0.5° beam step, so no beam changes side.
inline float fast_atan(float x) {
  const float ax = std::fabs(x);
  const bool invert = ax > 1.0f;
  // ±inf becomes 0 here and comes out as ±π/2, which the straight-down beam relies on.
  const float z = invert ? 1.0f / ax : ax;
  const float z2 = z * z;
  float r =
      z *
      (0.99997726f +
       z2 * (-0.33262347f +
             z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f + z2 * -0.01172120f)))));
  if (invert) r = 1.57079632679f - r;
  return std::copysign(r, x);
}

}  // namespace scanplan
