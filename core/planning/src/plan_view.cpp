#include "scanplan/planning/plan_view.hpp"

#include <opencv2/imgproc.hpp>
#include <string>

namespace scanplan {

void draw_plan(cv::Mat& img, const RegionMap& regions, const std::vector<Candidate>& ranked,
               std::optional<std::size_t> chosen, const TopViewStyle& style) {
  const int s = std::max(1, style.px_per_cell);
  const int radius = std::max(3, 2 * s);
  if (chosen && *chosen < ranked.size()) {
    const auto& path = ranked[*chosen].path;
    for (std::size_t k = 1; k < path.size(); ++k) {
      cv::line(img, top_view_pixel(regions, path[k - 1], style),
               top_view_pixel(regions, path[k], style), cv::Scalar(40, 160, 40), 2, cv::LINE_AA);
    }
  }
  for (std::size_t k = ranked.size(); k-- > 0;) {
    const cv::Point p = top_view_pixel(regions, ranked[k].position.head<2>(), style);
    const bool is_chosen = chosen && *chosen == k;
    cv::circle(img, p, radius, is_chosen ? cv::Scalar(40, 180, 40) : cv::Scalar(255, 255, 255),
               is_chosen ? -1 : 2, cv::LINE_AA);
    cv::putText(img, std::to_string(k + 1), p + cv::Point(radius + 2, -radius),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
}

}  // namespace scanplan
