#pragma once

namespace scanplan {

// The 3-D scanner: a 2-D laser range finder whose vertical fan turns on a rotation stage
// (paper §1, Fig. 1). Defaults are the workstation's contract (DESIGN.md "Scanner model").
struct ScannerConfig {
  double vertical_fov_deg = 180.0;  // fan from straight down to straight up
  double vertical_step_deg = 0.5;
  double rotation_deg = 360.0;
  double rotation_step_deg = 0.5;
  double min_range_m = 0.5;
  double max_range_m = 80.0;
  double range_noise_m = 0.01;  // 1σ
  double mount_height_m = 1.0;  // scanner centre above the ground under the robot
  double scan_duration_s = 60.0;
  // The colour camera: one equirectangular panorama per scan (height = width / 2), its optical
  // centre this far above the laser's.
  int camera_width_px = 1024;
  double camera_above_laser_m = 0.15;
  int camera_jpeg_quality = 90;

  int vertical_samples() const;
  int rotation_samples() const;
};

}  // namespace scanplan
