#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "scanplan/mapping/top_view.hpp"
#include "scanplan/planning/scan_planner.hpp"

namespace scanplan {

// Draws a plan over a regions top view (paper Fig. 5/7): each candidate as a numbered ring,
// the chosen one filled green with the path to it.
void draw_plan(cv::Mat& top_view, const RegionMap& regions, const std::vector<Candidate>& ranked,
               std::optional<std::size_t> chosen, const TopViewStyle& style = {});

}  // namespace scanplan
