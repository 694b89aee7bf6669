#include "scanplan/mapping/top_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace scanplan {
namespace {

const cv::Vec3b kOutside(24, 20, 20);  // BGR
const cv::Vec3b kUnscanned(64, 64, 64);
const cv::Vec3b kCompleted(180, 214, 250);     // flesh
const cv::Vec3b kLowMovable(64, 208, 236);     // yellow
const cv::Vec3b kLowNotMovable(200, 110, 70);  // blue
const cv::Vec3b kMovable(90, 190, 90);
const cv::Vec3b kData(150, 150, 150);

// Fills each cell of the regions' grid with fn(cell, region), north up.
template <typename Fn>
cv::Mat paint(const RegionMap& regions, const TopViewStyle& style, Fn&& fn) {
  const auto& g = regions.cells;
  const int s = std::max(1, style.px_per_cell);
  cv::Mat img(g.rows * s, g.cols * s, CV_8UC3);
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const CellIndex c{g.origin.x + i, g.origin.y + j};
      const cv::Vec3b color = fn(c, g.values[static_cast<std::size_t>(j) * g.cols + i]);
      img(cv::Rect(i * s, (g.rows - 1 - j) * s, s, s))
          .setTo(cv::Scalar(color[0], color[1], color[2]));
    }
  }
  return img;
}

}  // namespace

cv::Mat render_regions(const RegionMap& regions, const MovableRegion* movable,
                       const std::vector<Eigen::Vector2d>& scan_points, const TopViewStyle& style) {
  cv::Mat img = paint(regions, style, [&](CellIndex c, Region r) {
    switch (r) {
      case Region::kOutside:
        return kOutside;
      case Region::kUnscanned:
        return kUnscanned;
      case Region::kCompleted:
        return kCompleted;
      case Region::kLowResolution:
        return movable && movable->contains(c) ? kLowMovable : kLowNotMovable;
    }
    return kOutside;
  });
  const int s = std::max(1, style.px_per_cell);
  const int radius = std::max(3, 2 * s);
  for (std::size_t k = 0; k < scan_points.size(); ++k) {
    const bool first = k == 0, last = k + 1 == scan_points.size() && k > 0;
    const cv::Scalar color = first  ? cv::Scalar(220, 60, 20)
                             : last ? cv::Scalar(30, 30, 220)
                                    : cv::Scalar(40, 40, 40);
    const cv::Point p = top_view_pixel(regions, scan_points[k], style);
    cv::circle(img, p, radius, color, -1, cv::LINE_AA);
    cv::circle(img, p, radius, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return img;
}

std::optional<HeightRange> elevation_range(const MlsMap& map, const RegionMap& regions) {
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  const auto& g = regions.cells;
  for (std::size_t o = 0; o < g.values.size(); ++o) {
    if (g.values[o] == Region::kOutside) continue;
    if (const MlsCell* cell = map.cell(g.index_at(o))) {
      lo = std::min(lo, cell->dem_height());
      hi = std::max(hi, cell->dem_height());
    }
  }
  if (lo > hi) return std::nullopt;
  return HeightRange{lo, hi};
}

cv::Mat render_elevation(const MlsMap& map, const RegionMap& regions, const TopViewStyle& style) {
  const HeightRange range = elevation_range(map, regions).value_or(HeightRange{});
  const float lo = range.lo;
  const float span = range.hi > range.lo ? range.hi - range.lo : 1.0f;
  cv::Mat level = paint(regions, style, [&](CellIndex c, Region r) {
    const MlsCell* cell = r == Region::kOutside ? nullptr : map.cell(c);
    // Level 0 is kept for "no data"; heights use 1..255.
    const auto v = static_cast<std::uint8_t>(
        cell ? 1 + static_cast<int>(254.0f * (cell->dem_height() - lo) / span) : 0);
    return cv::Vec3b(v, v, v);
  });
  cv::Mat gray, colored;
  cv::extractChannel(level, gray, 0);
  cv::applyColorMap(gray, colored, cv::COLORMAP_TURBO);
  colored.setTo(cv::Scalar(kOutside[0], kOutside[1], kOutside[2]), gray == 0);
  return colored;
}

cv::Mat render_movable(const MlsMap& map, const MovableRegion& movable, const RegionMap& regions,
                       const TopViewStyle& style) {
  return paint(regions, style, [&](CellIndex c, Region r) {
    if (r == Region::kOutside) return kOutside;
    if (movable.contains(c)) return kMovable;
    return map.cell(c) ? kData : kUnscanned;
  });
}

cv::Point top_view_pixel(const RegionMap& regions, const Eigen::Vector2d& p,
                         const TopViewStyle& style) {
  const auto& g = regions.cells;
  const int s = std::max(1, style.px_per_cell);
  const double x = (p.x() / g.cell_m - g.origin.x) * s;
  const double y = (g.rows - (p.y() / g.cell_m - g.origin.y)) * s;
  return {static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y))};
}

std::vector<std::uint8_t> encode_png(const cv::Mat& bgr) {
  std::vector<std::uint8_t> out;
  if (!cv::imencode(".png", bgr, out)) throw std::runtime_error("PNG encoding failed");
  return out;
}

namespace {

constexpr int kBand = 28;  // px: a line of caption text
constexpr double kText = 0.45;

void text_at(cv::Mat& img, const std::string& text, cv::Point at) {
  cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, kText, cv::Scalar(235, 235, 235), 1,
              cv::LINE_AA);
}

int text_width(const std::string& text) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, kText, 1, &baseline).width;
}

}  // namespace

cv::Mat captioned_regions(const cv::Mat& top_view, const RegionMap& regions,
                          const std::string& title, const TopViewStyle& style) {
  struct Key {
    cv::Scalar colour;
    bool ring;  // a mark drawn as a circle (scan points, candidates) rather than a cell colour
    std::string label;
  };
  const auto cell = [](const cv::Vec3b& c) { return cv::Scalar(c[0], c[1], c[2]); };
  const std::vector<Key> keys = {
      {cell(kCompleted), false, "scan-completed (C)"},
      {cell(kLowMovable), false, "low resolution, movable (M)"},
      {cell(kLowNotMovable), false, "low resolution, not movable"},
      {cell(kUnscanned), false, "unscanned (U)"},
      {cell(kOutside), false, "outside the target region"},
      {cv::Scalar(220, 60, 20), true, "first scan"},
      {cv::Scalar(30, 30, 220), true, "latest scan"},
      {cv::Scalar(255, 255, 255), true, "candidate (rank)"},
      {cv::Scalar(40, 180, 40), true, "chosen, with its drive"},
  };
  // The legend flows over as many rows as the width needs.
  const int width = std::max(top_view.cols, 480);
  std::vector<std::vector<const Key*>> rows(1);
  int x = 8;
  for (const Key& k : keys) {
    const int w = 22 + text_width(k.label) + 14;
    if (x + w > width && !rows.back().empty()) {
      rows.emplace_back();
      x = 8;
    }
    rows.back().push_back(&k);
    x += w;
  }
  const int legend_h = kBand * static_cast<int>(rows.size() + 1);  // + the scale bar's row
  cv::Mat out(kBand + top_view.rows + legend_h, width, top_view.type(), cv::Scalar(30, 26, 24));
  top_view.copyTo(out(cv::Rect(0, kBand, top_view.cols, top_view.rows)));
  text_at(out, title, {8, kBand - 9});

  int y = kBand + top_view.rows + kBand - 9;
  for (const auto& row : rows) {
    x = 8;
    for (const Key* k : row) {
      const cv::Point c(x + 7, y - 4);
      if (k->ring) {
        cv::circle(out, c, 6, k->colour, -1, cv::LINE_AA);
        cv::circle(out, c, 6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
      } else {
        cv::rectangle(out, {x, y - 11}, {x + 14, y + 3}, k->colour, -1);
        cv::rectangle(out, {x, y - 11}, {x + 14, y + 3}, cv::Scalar(120, 120, 120), 1);
      }
      text_at(out, k->label, {x + 20, y});
      x += 22 + text_width(k->label) + 14;
    }
    y += kBand;
  }
  // A bar of a round length near a fifth of the image, and which way is north.
  const double px_per_m = style.px_per_cell / regions.cells.cell_m;
  double bar_m = 1;
  for (const double step : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0}) {
    if (step * px_per_m <= top_view.cols / 5.0) bar_m = step;
  }
  const int bar_px = static_cast<int>(std::lround(bar_m * px_per_m));
  cv::line(out, {8, y - 4}, {8 + bar_px, y - 4}, cv::Scalar(235, 235, 235), 2);
  cv::line(out, {8, y - 9}, {8, y + 1}, cv::Scalar(235, 235, 235), 2);
  cv::line(out, {8 + bar_px, y - 9}, {8 + bar_px, y + 1}, cv::Scalar(235, 235, 235), 2);
  char scale[96];
  std::snprintf(scale, sizeof scale, "%.0f m    north up, map frame", bar_m);
  text_at(out, scale, {16 + bar_px, y});
  return out;
}

}  // namespace scanplan
