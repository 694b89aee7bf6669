#include "ascii_top_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

namespace scanplan::cli {
namespace {

char region_char(RegionClass c) {
  switch (c) {
    case RegionClass::kOutside:
      return ' ';
    case RegionClass::kUnscanned:
      return '.';
    case RegionClass::kCompleted:
      return '#';
    case RegionClass::kLowMovable:
      return '+';
    case RegionClass::kLowNotMovable:
      return '=';
    case RegionClass::kUnknown:
      return '?';
  }
  return '?';
}

char rank_char(int rank) {
  if (rank >= 1 && rank <= 9) return static_cast<char>('0' + rank);
  if (rank >= 10 && rank <= 35) return static_cast<char>('A' + rank - 10);
  return '*';
}

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

// The most common known class among the raster's pixels inside [x0,x1) x [y0,y1), kUnknown
// when every pixel there is under a drawing, kOutside when the raster does not reach there.
RegionClass dominant(const RegionRaster& r, double x0, double x1, double y0, double y1) {
  const int c0 = std::max(0, static_cast<int>(std::floor((x0 - r.x_min) / r.m_per_px)));
  const int c1 = std::min(r.width, static_cast<int>(std::ceil((x1 - r.x_min) / r.m_per_px)));
  const int r0 = std::max(0, static_cast<int>(std::floor((r.y_max - y1) / r.m_per_px)));
  const int r1 = std::min(r.height, static_cast<int>(std::ceil((r.y_max - y0) / r.m_per_px)));
  if (c0 >= c1 || r0 >= r1) return RegionClass::kOutside;
  std::array<int, 6> count{};
  for (int row = r0; row < r1; ++row) {
    for (int col = c0; col < c1; ++col) ++count[static_cast<std::size_t>(r.at(col, row))];
  }
  RegionClass best = RegionClass::kUnknown;
  int best_count = 0;
  // kUnknown (index 0) is only the answer when nothing else is seen.
  for (std::size_t k = 1; k < count.size(); ++k) {
    if (count[k] > best_count) {
      best_count = count[k];
      best = static_cast<RegionClass>(k);
    }
  }
  return best;
}

}  // namespace

void zoom_to_known_area(TopViewInput& in, double margin_m) {
  double x0 = std::numeric_limits<double>::max(), y0 = x0;
  double x1 = std::numeric_limits<double>::lowest(), y1 = x1;
  const auto include = [&](double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  };
  if (const RegionRaster* r = in.regions) {
    for (int row = 0; row < r->height; ++row) {
      for (int col = 0; col < r->width; ++col) {
        const RegionClass c = r->at(col, row);
        if (c == RegionClass::kCompleted || c == RegionClass::kLowMovable ||
            c == RegionClass::kLowNotMovable) {
          include(r->x_min + col * r->m_per_px, r->y_max - row * r->m_per_px);
          include(r->x_min + (col + 1) * r->m_per_px, r->y_max - (row + 1) * r->m_per_px);
        }
      }
    }
  }
  for (const TopViewPoint& p : in.scan_points) include(p.x, p.y);
  for (const TopViewPoint& p : in.robots) include(p.x, p.y);
  for (const TopViewCandidate& c : in.candidates) include(c.x, c.y);
  if (x0 > x1) return;
  in.min_x = std::max(in.min_x, x0 - margin_m);
  in.max_x = std::min(in.max_x, x1 + margin_m);
  in.min_y = std::max(in.min_y, y0 - margin_m);
  in.max_y = std::min(in.max_y, y1 + margin_m);
}

std::vector<std::string> render_ascii_top_view(const TopViewInput& in, const TopViewSize& size) {
  const double w = std::max(in.max_x - in.min_x, 1e-6), h = std::max(in.max_y - in.min_y, 1e-6);
  const int max_cols = std::max(1, size.max_cols), max_rows = std::max(1, size.max_rows);
  const double aspect = size.char_aspect > 0 ? size.char_aspect : 2.0;
  const double mx = std::max(w / max_cols, h / (max_rows * aspect));  // metres a column
  const double my = mx * aspect;                                      // metres a row
  const int cols = std::clamp(static_cast<int>(std::ceil(w / mx - 1e-9)), 1, max_cols);
  const int rows = std::clamp(static_cast<int>(std::ceil(h / my - 1e-9)), 1, max_rows);

  std::vector<std::string> grid(static_cast<std::size_t>(rows), std::string(cols, ' '));
  if (in.regions) {
    for (int row = 0; row < rows; ++row) {
      const double y1 = in.max_y - row * my, y0 = y1 - my;
      for (int col = 0; col < cols; ++col) {
        const double x0 = in.min_x + col * mx;
        grid[static_cast<std::size_t>(row)][static_cast<std::size_t>(col)] =
            region_char(dominant(*in.regions, x0, x0 + mx, y0, y1));
      }
    }
  }
  const auto put = [&](double x, double y, char c) {
    if (!std::isfinite(x) || !std::isfinite(y) || x < in.min_x || x > in.max_x || y < in.min_y ||
        y > in.max_y) {
      return;
    }
    const int col = std::min(cols - 1, static_cast<int>((x - in.min_x) / mx));
    const int row = std::min(rows - 1, static_cast<int>((in.max_y - y) / my));
    grid[static_cast<std::size_t>(row)][static_cast<std::size_t>(col)] = c;
  };
  for (const TopViewPoint& p : in.scan_points) put(p.x, p.y, 'o');
  for (const TopViewPoint& p : in.robots) put(p.x, p.y, 'R');
  std::vector<TopViewCandidate> by_rank = in.candidates;
  // Worst rank first so that the best one stays visible where two share a character.
  std::sort(by_rank.begin(), by_rank.end(),
            [](const TopViewCandidate& a, const TopViewCandidate& b) { return a.rank > b.rank; });
  for (const TopViewCandidate& c : by_rank) put(c.x, c.y, rank_char(c.rank));

  std::vector<std::string> out;
  char scale[160];
  std::snprintf(scale, sizeof scale, "north up; x %s..%s m, y %s..%s m; 1 char = %.1f m x %.1f m",
                metres(in.min_x).c_str(), metres(in.max_x).c_str(), metres(in.min_y).c_str(),
                metres(in.max_y).c_str(), mx, my);
  out.emplace_back(scale);
  const std::string border = "+" + std::string(static_cast<std::size_t>(cols), '-') + "+";
  out.push_back(border);
  for (const std::string& line : grid) out.push_back("|" + line + "|");
  out.push_back(border);
  std::string regions = "# completed  + low-res, drivable  = low-res, not drivable  . unscanned";
  if (std::any_of(grid.begin(), grid.end(),
                  [](const std::string& line) { return line.find('?') != std::string::npos; })) {
    regions += "  ? under drawings";
  }
  out.push_back(regions);
  std::string markers = "o scan point  R robot  1-9 candidates by rank";
  if (std::any_of(in.candidates.begin(), in.candidates.end(),
                  [](const TopViewCandidate& c) { return c.rank > 9; })) {
    markers += ", A-Z ranks 10-35";
  }
  out.push_back(markers);
  return out;
}

}  // namespace scanplan::cli
