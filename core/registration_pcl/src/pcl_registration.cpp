#include "scanplan/registration_pcl/pcl_registration.hpp"

// GCC 12 flags Eigen's packet loads inside PCL's SVD transformation estimation as reading past a
// 3-vector (-Warray-bounds); the code is PCL's and Eigen's, not ours, and the warning is known to
// be spurious there.
#pragma GCC diagnostic ignored "-Warray-bounds"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

#include <array>
#include <string>
#include <utility>

namespace scanplan {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr to_pcl(const PointCloud& cloud) {
  auto out = pcl::make_shared<Cloud>();
  out->reserve(cloud.size());
  for (const auto& p : cloud.points) out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return out;
}

// PCL keeps the iteration count of ICP and GICP protected; these expose it.
template <typename Base>
struct Counted : Base {
  int iterations() const { return this->nr_iterations_; }
};

template <typename Matcher>
RegistrationResult run(Matcher& matcher, const PointCloud& target, const PointCloud& source,
                       const Eigen::Isometry3d& initial) {
  matcher.setInputTarget(to_pcl(target));
  matcher.setInputSource(to_pcl(source));
  Cloud aligned;
  matcher.align(aligned, initial.matrix().cast<float>());
  RegistrationResult result;
  result.transform.matrix() = matcher.getFinalTransformation().template cast<double>();
  // PCL's float transform is not quite orthonormal; ours must be.
  result.transform.linear() =
      Eigen::Quaterniond(result.transform.linear()).normalized().toRotationMatrix();
  result.converged = matcher.hasConverged();
  result.iterations = matcher.iterations();
  if (!result.converged) result.message = "PCL reports no convergence";
  return result;
}

}  // namespace

RegistrationResult align_pcl(const PointCloud& target, const PointCloud& source,
                             const Eigen::Isometry3d& initial, PclMethod method, Dof dof,
                             const PclConfig& config) {
  RegistrationResult result;
  if (target.size() < 2 || source.empty()) {
    result.message = "PCL matching needs at least two target points and one source point";
    result.transform = initial;
  } else if (method == PclMethod::kNdt) {
    Counted<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>> ndt;
    ndt.setResolution(static_cast<float>(config.ndt_resolution_m));
    ndt.setStepSize(config.ndt_step_size_m);
    ndt.setMaximumIterations(config.max_iterations);
    ndt.setTransformationEpsilon(config.transformation_epsilon);
    result = run(ndt, target, source, initial);
  } else if (method == PclMethod::kIcp) {
    Counted<pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>> icp;
    icp.setMaxCorrespondenceDistance(config.icp_max_correspondence_m);
    icp.setMaximumIterations(config.max_iterations);
    icp.setTransformationEpsilon(config.transformation_epsilon);
    icp.setEuclideanFitnessEpsilon(config.euclidean_fitness_epsilon);
    result = run(icp, target, source, initial);
  } else {
    Counted<pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>> gicp;
    gicp.setMaxCorrespondenceDistance(config.gicp_max_correspondence_m);
    gicp.setMaximumIterations(config.max_iterations);
    gicp.setTransformationEpsilon(config.transformation_epsilon);
    gicp.setEuclideanFitnessEpsilon(config.euclidean_fitness_epsilon);
    result = run(gicp, target, source, initial);
  }
  result.method = method == PclMethod::kNdt   ? "pcl-ndt"
                  : method == PclMethod::kIcp ? "pcl-icp"
                                              : "pcl-gicp";
  if (dof == Dof::k4) {
    const std::string note = "PCL solves 6 DOF; roll and pitch were not held";
    result.message = result.message.empty() ? note : result.message + "; " + note;
  }
  return result;
}

namespace {

constexpr std::array<std::pair<PclMethod, std::string_view>, 3> kPclNames{{
    {PclMethod::kNdt, "pcl-ndt"},
    {PclMethod::kIcp, "pcl-icp"},
    {PclMethod::kGicp, "pcl-gicp"},
}};

std::string_view pcl_name(PclMethod method) {
  for (const auto& [m, text] : kPclNames) {
    if (m == method) return text;
  }
  return "unknown";
}

}  // namespace

PclConfig scale_lengths(const PclConfig& config, double factor) {
  PclConfig c = config;
  c.ndt_resolution_m *= factor;
  c.ndt_step_size_m *= factor;
  c.icp_max_correspondence_m *= factor;
  c.gicp_max_correspondence_m *= factor;
  return c;
}

RegistrationResult register_scans(const PointCloud& target, const PointCloud& source,
                                  const Eigen::Isometry3d& initial, PclMethod method,
                                  const RegistrationConfig& config, const PclConfig& pcl) {
  return register_with(
      target, source, initial, pcl_name(method),
      [method, &pcl](const PointCloud& t, const PointCloud& s, const Eigen::Isometry3d& start,
                     const RegistrationConfig& c, double scale, const MatchViews&) {
        return align_pcl(t, s, start, method, c.dof, scale_lengths(pcl, scale));
      },
      config);
}

std::optional<AnyMethod> parse_any_method(std::string_view name) {
  if (const auto ours = parse_method(name)) return AnyMethod{*ours};
  for (const auto& [m, text] : kPclNames) {
    if (text == name) return AnyMethod{m};
  }
  return std::nullopt;
}

std::string_view any_method_name(AnyMethod method) {
  if (const auto* ours = std::get_if<Method>(&method)) return method_name(*ours);
  return pcl_name(std::get<PclMethod>(method));
}

RegistrationResult register_any(const PointCloud& target, const PointCloud& source,
                                const Eigen::Isometry3d& initial, AnyMethod method,
                                const RegistrationConfig& config, const PclConfig& pcl) {
  if (const auto* ours = std::get_if<Method>(&method)) {
    return register_scans(target, source, initial, *ours, config);
  }
  return register_scans(target, source, initial, std::get<PclMethod>(method), config, pcl);
}

}  // namespace scanplan
