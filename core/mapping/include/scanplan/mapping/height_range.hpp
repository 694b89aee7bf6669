#pragma once

namespace scanplan {

// A span of heights in metres (z in the map frame), lowest first; e.g. the ends of the elevation
// top view's colour scale. Its own header so that code which passes it along does not pull in
// OpenCV with the top views.
struct HeightRange {
  float lo = 0, hi = 0;
};

}  // namespace scanplan
