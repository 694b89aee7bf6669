#include "scanplan/geometry/pose_limits.hpp"

#include <cmath>
#include <cstdio>

namespace scanplan {

std::optional<std::string> implausible_pose(const Pose& pose, const PoseLimits& limits) {
  struct Field {
    const char* name;
    double value;
    double limit;
    const char* unit;
  };
  const Field fields[] = {
      {"x", pose.x, limits.max_xy_m, " m"},
      {"y", pose.y, limits.max_xy_m, " m"},
      {"z", pose.z, limits.max_z_m, " m"},
      {"roll", rad2deg(pose.roll), limits.max_angle_deg, "°"},
      {"pitch", rad2deg(pose.pitch), limits.max_angle_deg, "°"},
      {"yaw", rad2deg(pose.yaw), limits.max_angle_deg, "°"},
  };
  for (const Field& f : fields) {
    if (std::isfinite(f.value) && std::abs(f.value) <= f.limit) continue;
    char buf[160];
    std::snprintf(buf, sizeof buf, "the pose's %s is %g%s; it must be finite and within ±%g%s",
                  f.name, f.value, f.unit, f.limit, f.unit);
    return std::string(buf);
  }
  return std::nullopt;
}

}  // namespace scanplan
