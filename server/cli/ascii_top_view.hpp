#pragma once

#include <string>
#include <vector>

#include "region_raster.hpp"

namespace scanplan::cli {

struct TopViewPoint {
  double x = 0, y = 0;
};

struct TopViewCandidate {
  int rank = 0;
  double x = 0, y = 0;
};

// What the terminal top view shows, all in the map frame (metres).
struct TopViewInput {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // the area shown, e.g. the target region
  const RegionRaster* regions = nullptr;              // C / M / U; null draws the markers on blank
  std::vector<TopViewPoint> scan_points;
  std::vector<TopViewPoint> robots;
  std::vector<TopViewCandidate> candidates;
};

// The part of in's area worth showing: the cells with data (completed or low resolution), the
// scan points, robots and candidates, with margin_m around them, within in's area. A 200 m
// target region around a first scan of a small site would otherwise put everything of interest
// in a few characters. in's area itself when there is nothing yet.
void zoom_to_known_area(TopViewInput& in, double margin_m = 5.0);

// At most max_cols x max_rows characters for the map itself. Terminal cells are about twice as
// tall as wide, so a character row spans char_aspect times the metres of a column and the map
// keeps its shape.
struct TopViewSize {
  int max_cols = 60;
  int max_rows = 20;
  double char_aspect = 2.0;
};

// A north-up ASCII drawing for terminals on a poor link: a header with the extent and scale,
// the framed map and a legend. Each character takes the most common region among the pixels
// it covers ('#' completed, '+' low resolution where the robot can drive, '=' where it cannot,
// '.' unscanned, ' ' outside the target region, '?' only drawings); over them 'o' marks a scan
// point, 'R' a robot and '1'-'9', then 'A'-'Z' for ranks 10-35, '*' beyond, the candidates,
// the better rank on top where they share a character.
std::vector<std::string> render_ascii_top_view(const TopViewInput& in,
                                               const TopViewSize& size = {});

}  // namespace scanplan::cli
