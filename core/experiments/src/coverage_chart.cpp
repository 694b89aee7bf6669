#include "scanplan/experiments/coverage_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace scanplan {
namespace {

// 1, 2 or 5 times a power of ten: about `ticks` steps over `range`.
double nice_step(double range, int ticks) {
  const double raw = range / ticks;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

std::string tick_label(double v) {
  char buf[32];
  if (std::abs(v) >= 10000) {
    std::snprintf(buf, sizeof buf, "%.0fk", v / 1000);
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

struct Stats {
  std::vector<double> mean, sd;
};

// Mean and sample sd per scan; a run shorter than the longest holds its last value.
Stats stats_of(const ChartSeries& s, std::size_t length) {
  Stats out;
  for (std::size_t k = 0; k < length; ++k) {
    double sum = 0, sum2 = 0;
    std::size_t n = 0;
    for (const auto& run : s.runs) {
      if (run.empty()) continue;
      const double v = run[std::min(k, run.size() - 1)];
      sum += v;
      sum2 += v * v;
      ++n;
    }
    const auto count = static_cast<double>(n);
    const double m = n ? sum / count : 0;
    out.mean.push_back(m);
    out.sd.push_back(n > 1 ? std::sqrt(std::max(0.0, (sum2 - count * m * m) / (count - 1))) : 0);
  }
  return out;
}

// Where the plot lies in the image, and the map from (scan, value) to pixels.
struct Frame {
  static constexpr int kLeft = 62, kRight = 12, kTop = 30, kBottom = 42;
  int left = kLeft, top = kTop, pw = 0, ph = 0;
  std::size_t length = 0;  // scans on the x axis
  double y_top = 1;
  cv::Point px(double scan, double y) const {
    const double fx = length > 1 ? (scan - 1) / static_cast<double>(length - 1) : 0.5;
    return cv::Point(left + static_cast<int>(std::lround(fx * pw)),
                     top + ph - static_cast<int>(std::lround(y / y_top * ph)));
  }
};

const auto kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225);

// The grid, the ticks, the titles and the dashed reference lines.
void draw_axes(cv::Mat& img, const Frame& f, const ChartStyle& style, double y_step,
               double x_step) {
  for (double y = 0; y <= f.y_top + 1e-9; y += y_step) {
    const cv::Point a = f.px(1, y);
    cv::line(img, a, {f.left + f.pw, a.y}, kGrid, 1);
    const std::string t = tick_label(y);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, kFont, 0.4, 1, &base);
    cv::putText(img, t, {f.left - 6 - sz.width, a.y + 4}, kFont, 0.4, kInk, 1, cv::LINE_AA);
  }
  for (double x = x_step; x <= static_cast<double>(f.length) + 1e-9; x += x_step) {
    const cv::Point a = f.px(x, 0);
    cv::line(img, {a.x, f.top}, {a.x, f.top + f.ph}, kGrid, 1);
    cv::putText(img, tick_label(x), {a.x - 6, f.top + f.ph + 16}, kFont, 0.4, kInk, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {f.left, f.top}, {f.left + f.pw, f.top + f.ph}, kInk, 1);
  cv::putText(img, "scans", {f.left + f.pw / 2 - 20, style.height_px - 8}, kFont, 0.45, kInk, 1,
              cv::LINE_AA);
  cv::putText(img, style.title, {f.left, 20}, kFont, 0.5, kInk, 1, cv::LINE_AA);
  if (!style.y_label.empty()) {
    cv::Mat label(18, f.ph, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, style.y_label, {4, 13}, kFont, 0.4, kInk, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    rotated.copyTo(img(cv::Rect(2, f.top, rotated.cols, rotated.rows)));
  }
  for (const auto& r : style.references) {
    const cv::Point a = f.px(1, r.y);
    for (int x = f.left; x < f.left + f.pw; x += 10)
      cv::line(img, {x, a.y}, {std::min(x + 5, f.left + f.pw), a.y}, kInk, 1);
    int base = 0;
    const cv::Size sz = cv::getTextSize(r.label, kFont, 0.38, 1, &base);
    cv::putText(img, r.label, {f.left + f.pw - 6 - sz.width, a.y - 4}, kFont, 0.38, kInk, 1,
                cv::LINE_AA);
  }
}

// Each series' mean as a line, its spread (mean ± sd over runs) as a band, and a legend.
void draw_series(cv::Mat& img, const Frame& f, const std::vector<ChartSeries>& series) {
  // Bands first, blended, so that no line hides under another policy's band.
  cv::Mat bands = img.clone();
  std::vector<Stats> all;
  for (const auto& s : series) {
    all.push_back(stats_of(s, f.length));
    const Stats& st = all.back();
    if (s.runs.size() < 2) continue;
    std::vector<cv::Point> poly;
    for (std::size_t k = 0; k < f.length; ++k)
      poly.push_back(f.px(static_cast<double>(k + 1), std::min(f.y_top, st.mean[k] + st.sd[k])));
    for (std::size_t k = f.length; k-- > 0;)
      poly.push_back(f.px(static_cast<double>(k + 1), std::max(0.0, st.mean[k] - st.sd[k])));
    cv::fillPoly(bands, std::vector<std::vector<cv::Point>>{poly}, s.color, cv::LINE_AA);
  }
  cv::addWeighted(bands, 0.25, img, 0.75, 0, img);
  for (std::size_t i = 0; i < series.size(); ++i) {
    std::vector<cv::Point> line;
    for (std::size_t k = 0; k < f.length; ++k)
      line.push_back(f.px(static_cast<double>(k + 1), all[i].mean[k]));
    cv::polylines(img, line, false, series[i].color, 2, cv::LINE_AA);
    const int ly = f.top + 14 + static_cast<int>(i) * 16;
    const int lx = f.left + 10;
    cv::line(img, {lx, ly - 4}, {lx + 18, ly - 4}, series[i].color, 2, cv::LINE_AA);
    cv::putText(img, series[i].name, {lx + 24, ly}, kFont, 0.4, kInk, 1, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat render_coverage_chart(const std::vector<ChartSeries>& series, const ChartStyle& style) {
  std::size_t length = 0;
  double y_max = 0;
  for (const auto& s : series) {
    for (const auto& run : s.runs) {
      length = std::max(length, run.size());
      for (const double v : run) {
        if (!std::isfinite(v))
          throw std::invalid_argument("chart: series '" + s.name +
                                      "' has a value that is not a number");
        y_max = std::max(y_max, v);
      }
    }
  }
  if (length == 0) throw std::invalid_argument("chart: no series has any value");
  for (const auto& r : style.references) y_max = std::max(y_max, r.y);
  if (y_max <= 0) y_max = 1;
  const double y_step = nice_step(y_max, 5);
  Frame f;
  f.length = length;
  f.y_top = std::ceil(y_max * 1.02 / y_step) * y_step;
  f.pw = style.width_px - Frame::kLeft - Frame::kRight;
  f.ph = style.height_px - Frame::kTop - Frame::kBottom;
  const double x_step = std::max(1.0, std::round(nice_step(static_cast<double>(length), 8)));
  cv::Mat img(style.height_px, style.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  draw_axes(img, f, style, y_step, x_step);
  draw_series(img, f, series);
  return img;
}

}  // namespace scanplan
