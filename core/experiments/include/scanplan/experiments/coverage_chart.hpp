#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace scanplan {

// One policy's runs of a quantity over scans: runs[r][k] is the value after scan k + 1 of run r.
// Runs that stopped early (coverage reached) keep their last value for the later scans, so the
// mean is over every run at every scan.
struct ChartSeries {
  std::string name;
  cv::Scalar color;  // BGR
  std::vector<std::vector<double>> runs;
};

struct ChartStyle {
  int width_px = 640;
  int height_px = 420;
  std::string title;
  std::string y_label;
  // Horizontal reference lines (a target, a figure from the paper) with their labels.
  struct Reference {
    double y = 0;
    std::string label;
  };
  std::vector<Reference> references;
};

// A line chart of the series against the scan number: the mean of the runs as a line and,
// where there is more than one run, a band of ± one standard deviation, with axes, ticks
// and a legend. Throws std::invalid_argument when no series has any value or a value is not
// finite.
cv::Mat render_coverage_chart(const std::vector<ChartSeries>& series, const ChartStyle& style);

}  // namespace scanplan
