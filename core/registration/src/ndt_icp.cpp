#include "scanplan/registration/ndt_icp.hpp"

#include <algorithm>

namespace scanplan {

RegistrationResult align_ndt_icp(const PointCloud& target, const PointCloud& source,
                                 const Eigen::Isometry3d& initial, Dof dof, const NdtConfig& ndt,
                                 const IcpConfig& icp) {
  const RegistrationResult coarse = align_narrower_ndt(target, source, initial, dof, ndt);

  // An NDT that ran out of iterations has usually still moved the right way, so ICP goes on
  // from it; one that found no overlap at all leaves nothing for ICP to refine.
  const bool usable = coarse.converged || coarse.iterations > 0;
  // After a converged NDT the remaining error is a fraction of its finest cell, so ICP need not
  // look as far for partners as it would from a raw initial guess; nearer partners are also
  // found faster.
  IcpConfig refine = icp;
  if (coarse.converged) {
    refine.max_correspondence_m = std::min(icp.max_correspondence_m, 2 * icp.min_correspondence_m);
  }
  RegistrationResult fine =
      align_line_segment_icp(target, source, usable ? coarse.transform : initial, dof, refine);
  fine.method = "ndt-icp";
  fine.iterations += coarse.iterations;
  if (!coarse.converged && !coarse.message.empty()) {
    fine.message = fine.message.empty() ? "NDT stage: " + coarse.message
                                        : fine.message + "; NDT stage: " + coarse.message;
  }
  return fine;
}

}  // namespace scanplan
