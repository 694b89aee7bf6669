#include "scanplan/geometry/viewpoints.hpp"

#include <algorithm>

namespace scanplan {

bool Viewpoints::fit(std::size_t points) const {
  if (origins.empty()) return false;
  if (origin_of.empty()) return true;
  return origin_of.size() == points &&
         std::all_of(origin_of.begin(), origin_of.end(),
                     [&](std::uint32_t o) { return o < origins.size(); });
}

Viewpoints Viewpoints::picked(const std::vector<std::uint32_t>& kept) const {
  Viewpoints out;
  out.origins = origins;
  if (origin_of.empty()) return out;
  out.origin_of.reserve(kept.size());
  for (const std::uint32_t i : kept) out.origin_of.push_back(origin_of[i]);
  return out;
}

Viewpoints Viewpoints::transformed(const Eigen::Isometry3f& t) const {
  Viewpoints out = *this;
  for (Eigen::Vector3f& o : out.origins) o = t * o;
  return out;
}

}  // namespace scanplan
