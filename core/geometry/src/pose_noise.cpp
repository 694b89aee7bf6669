#include "scanplan/geometry/pose_noise.hpp"

namespace scanplan {

std::optional<OdometryModel> parse_odometry_model(std::string_view name) {
  if (name == "drift") return OdometryModel::kDrift;
  if (name == "absolute") return OdometryModel::kAbsolute;
  return std::nullopt;
}

std::string_view odometry_model_name(OdometryModel model) {
  return model == OdometryModel::kDrift ? "drift" : "absolute";
}

}  // namespace scanplan
