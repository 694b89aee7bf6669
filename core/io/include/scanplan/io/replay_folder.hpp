#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan {

// Thrown when a replay folder's listing cannot be used: the message names the folder or file,
// the line of poses.csv where that applies, and what is wrong.
class ReplayFolderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A directory of recorded scans to play back in order, in one of two layouts:
//  (a) scan files (*.ply, *.pcd) listed in `poses.csv`, header `file,x,y,z,yaw_deg` plus
//      optionally `roll_deg,pitch_deg` (any column order, no quoting), one row per scan in
//      playing order; `file` is relative to the folder. An image `<stem>.jpg` beside a scan
//      is that scan's camera image.
//  (b) a 3DTK folder: `scanNNN.3d` with `scanNNN.pose` (odometry), ordered by NNN.
// When poses.csv exists it wins. Poses are the robot's estimated poses (metres, radians);
// points in the files are in the scanner/robot frame (DESIGN.md).
//
// The constructor checks the whole listing so that a bad folder fails before playback starts;
// point data is read only by load(), so one broken scan costs only that scan.
class ReplayFolder {
 public:
  struct Entry {
    std::filesystem::path scan;
    Pose pose;
    std::optional<std::filesystem::path> image;
  };

  explicit ReplayFolder(std::filesystem::path dir);

  const std::filesystem::path& dir() const { return dir_; }
  std::size_t size() const { return entries_.size(); }
  // Throws std::out_of_range for i >= size().
  const Entry& entry(std::size_t i) const;
  // Reads scan i; throws ScanFileError (naming the file) if it is broken.
  PointCloud load(std::size_t i) const;

 private:
  void list_csv(const std::filesystem::path& csv);
  void list_threedtk();
  std::optional<std::filesystem::path> image_beside(const std::filesystem::path& scan) const;

  std::filesystem::path dir_;
  std::vector<Entry> entries_;
};

}  // namespace scanplan
