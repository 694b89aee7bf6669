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
    const double m = n ? sum / n : 0;
    out.mean.push_back(m);
    out.sd.push_back(n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * m * m) / (n - 1))) : 0);
  }
  return out;
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
  const double y_top = std::ceil(y_max * 1.02 / y_step) * y_step;
  const double x_step = std::max(1.0, std::round(nice_step(static_cast<double>(length), 8)));

  const int left = 62, right = 12, top = 30, bottom = 42;
  cv::Mat img(style.height_px, style.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  const int pw = style.width_px - left - right, ph = style.height_px - top - bottom;
  const auto px = [&](double scan, double y) {
    const double fx = length > 1 ? (scan - 1) / static_cast<double>(length - 1) : 0.5;
    return cv::Point(left + static_cast<int>(std::lround(fx * pw)),
                     top + ph - static_cast<int>(std::lround(y / y_top * ph)));
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar ink(40, 40, 40), grid(225, 225, 225);

  for (double y = 0; y <= y_top + 1e-9; y += y_step) {
    const cv::Point a = px(1, y);
    cv::line(img, a, {left + pw, a.y}, grid, 1);
    const std::string t = tick_label(y);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.4, 1, &base);
    cv::putText(img, t, {left - 6 - sz.width, a.y + 4}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  for (double x = x_step; x <= static_cast<double>(length) + 1e-9; x += x_step) {
    const cv::Point a = px(x, 0);
    cv::line(img, {a.x, top}, {a.x, top + ph}, grid, 1);
    const std::string t = tick_label(x);
    cv::putText(img, t, {a.x - 6, top + ph + 16}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {left, top}, {left + pw, top + ph}, ink, 1);
  cv::putText(img, "scans", {left + pw / 2 - 20, style.height_px - 8}, font, 0.45, ink, 1,
              cv::LINE_AA);
  cv::putText(img, style.title, {left, 20}, font, 0.5, ink, 1, cv::LINE_AA);
  if (!style.y_label.empty()) {
    cv::Mat label(18, ph, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, style.y_label, {4, 13}, font, 0.4, ink, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    rotated.copyTo(img(cv::Rect(2, top, rotated.cols, rotated.rows)));
  }
  for (const auto& r : style.references) {
    const cv::Point a = px(1, r.y);
    for (int x = left; x < left + pw; x += 10)
      cv::line(img, {x, a.y}, {std::min(x + 5, left + pw), a.y}, ink, 1);
    int base = 0;
    const cv::Size sz = cv::getTextSize(r.label, font, 0.38, 1, &base);
    cv::putText(img, r.label, {left + pw - 6 - sz.width, a.y - 4}, font, 0.38, ink, 1, cv::LINE_AA);
  }

  // Bands first, blended, so that no line hides under another policy's band.
  cv::Mat bands = img.clone();
  std::vector<Stats> all;
  for (const auto& s : series) {
    all.push_back(stats_of(s, length));
    const Stats& st = all.back();
    if (s.runs.size() < 2) continue;
    std::vector<cv::Point> poly;
    for (std::size_t k = 0; k < length; ++k)
      poly.push_back(px(static_cast<double>(k + 1), std::min(y_top, st.mean[k] + st.sd[k])));
    for (std::size_t k = length; k-- > 0;)
      poly.push_back(px(static_cast<double>(k + 1), std::max(0.0, st.mean[k] - st.sd[k])));
    cv::fillPoly(bands, std::vector<std::vector<cv::Point>>{poly}, s.color, cv::LINE_AA);
  }
  cv::addWeighted(bands, 0.25, img, 0.75, 0, img);
  for (std::size_t i = 0; i < series.size(); ++i) {
    std::vector<cv::Point> line;
    for (std::size_t k = 0; k < length; ++k)
      line.push_back(px(static_cast<double>(k + 1), all[i].mean[k]));
    cv::polylines(img, line, false, series[i].color, 2, cv::LINE_AA);
    const int ly = top + 14 + static_cast<int>(i) * 16;
    const int lx = left + 10;
    cv::line(img, {lx, ly - 4}, {lx + 18, ly - 4}, series[i].color, 2, cv::LINE_AA);
    cv::putText(img, series[i].name, {lx + 24, ly}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  return img;
}

}  // namespace scanplan
