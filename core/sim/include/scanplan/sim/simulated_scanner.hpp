#pragma once

#include <cstdint>
#include <functional>
#include <random>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/scanner_model.hpp"
#include "scanplan/sim/ray_caster.hpp"

namespace scanplan {

// Called with the fraction of the rotation done, in [0, 1]; returning false aborts the scan.
using ScanProgressFn = std::function<bool(double fraction)>;

// One full turn of the rotation stage at `true_pose`. Points are in the robot frame (origin on
// the ground under the scanner, x forward, z up), ordered by stage angle then elevation; sky
// and out-of-range beams give no point. Stage angles are shared among `num_threads` OpenMP
// threads (0: the OpenMP default). Each stage angle draws its range noise from its own stream
// derived from `seed`, so the same seed gives the same scan whatever the thread count.
// `progress` is called on the calling thread only, in order.
PointCloud simulate_scan(const RayCaster& caster, const ScannerConfig& config,
                         const Pose& true_pose, std::uint64_t seed,
                         const ScanProgressFn& progress = {}, int num_threads = 0);

}  // namespace scanplan
