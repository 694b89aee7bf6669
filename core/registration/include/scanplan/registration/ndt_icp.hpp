#pragma once

#include <Eigen/Geometry>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/line_segment_icp.hpp"
#include "scanplan/registration/narrower_ndt.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

// The paper's combination (§4.3): ICP is the more accurate when it succeeds but falls into local
// minima far more easily than NDT, so narrower NDT brings the scans together first and
// line-segment ICP refines from where it stopped. Converged is the ICP's verdict; the iterations
// of both are summed.
RegistrationResult align_ndt_icp(const PointCloud& target, const PointCloud& source,
                                 const Eigen::Isometry3d& initial, Dof dof, const NdtConfig& ndt,
                                 const IcpConfig& icp);

}  // namespace scanplan
