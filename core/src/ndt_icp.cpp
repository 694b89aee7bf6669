#include <chrono>
#include <cstdio>
#include "scanplan/core/ndt_icp.hpp"

namespace scanplan {

RegistrationResult align_ndt_icp(const PointCloud& target, const PointCloud& source,
                                 const Eigen::Isometry3d& initial, Dof dof, const NdtConfig& ndt,
                                 const IcpConfig& icp) {
  auto t0 = std::chrono::steady_clock::now();
  const RegistrationResult coarse = align_narrower_ndt(target, source, initial, dof, ndt);
  auto t1 = std::chrono::steady_clock::now();
  // An NDT that ran out of iterations has usually still moved the right way, so ICP goes on
  // from it; one that found no overlap at all leaves nothing for ICP to refine.
  const bool usable = coarse.converged || coarse.iterations > 0;
  RegistrationResult fine = align_line_segment_icp(
      target, source, usable ? coarse.transform : initial, dof, icp);
  auto t2 = std::chrono::steady_clock::now();
  fprintf(stderr, "TIMING ndt %.1f ms (%d it) icp %.1f ms (%d it)\n", std::chrono::duration<double, std::milli>(t1-t0).count(), coarse.iterations, std::chrono::duration<double, std::milli>(t2-t1).count(), fine.iterations);
  fine.method = "ndt-icp";
  fine.iterations += coarse.iterations;
  if (!coarse.converged && !coarse.message.empty()) {
    fine.message = fine.message.empty() ? "NDT stage: " + coarse.message
                                        : fine.message + "; NDT stage: " + coarse.message;
  }
  return fine;
}

}  // namespace scanplan
