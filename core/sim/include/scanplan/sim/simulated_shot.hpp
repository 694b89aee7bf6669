#pragma once

#include <opencv2/core.hpp>

#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {

// What the simulated scanner hands over after one turn: the laser's points (robot frame, no
// colour: the laser sees none) and the camera's panorama with its calibration.
struct SimulatedShot {
  PointCloud cloud;
  cv::Mat panorama;  // 8-bit BGR
  PanoramaCamera camera;
};

// One full scan and one panorama at `true_pose`; nothing when `progress` aborted the scan.
std::optional<SimulatedShot> simulate_shot(const RayCaster& caster, const ScannerConfig& scanner,
                                           const Pose& true_pose, std::uint64_t seed,
                                           const ScanProgressFn& progress = {});

}  // namespace scanplan
