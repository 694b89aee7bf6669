#pragma once

#include <cstdint>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// One point per occupied cube of side `voxel_m`: the measured point nearest the centroid of the
// points in it. A scan from a rotating fan is dense near the scanner and sparse far away;
// thinning evens that out so that matching is not dominated by the ground at the robot's feet.
// A measured point rather than the centroid itself: where a cube holds a corner, an edge or a
// partly occluded surface, the centroid lies off every surface, at a place that depends on where
// the scanner stood, and two scans of the same corner disagree by up to half a cube — a bias
// that matching then reproduces (measured on the campus: several cm). Colours are not kept.
// Non-finite points, and points more than about 10^6 voxels from the origin, are left out. voxel_m
// <= 0 returns the finite points unchanged. The output is ordered by voxel, so the same input
// always gives the same output.
PointCloud voxel_downsample(const PointCloud& cloud, double voxel_m);
// The indices of the points voxel_downsample keeps, in its order: for what travels with the
// points (their viewpoints).
std::vector<std::uint32_t> voxel_kept(const PointCloud& cloud, double voxel_m);
// The points `kept` (indices into `cloud`), in that order; colours kept when the cloud has them.
PointCloud picked(const PointCloud& cloud, const std::vector<std::uint32_t>& kept);

// A growing map thinned to one point per cube of side `voxel_m`, for sending the whole map
// where bandwidth matters (the server's DDS map topic). Each scan added is thinned as
// voxel_downsample does, colours kept; a cube the map already holds keeps its first point, so
// the thinned map only grows and a subscriber sees settled areas stay put. Adding costs time
// linear in the map's size (one merge of sorted lists), not a pass over every point so far.
class VoxelMap {
 public:
  // Throws std::invalid_argument unless voxel_m > 0.
  explicit VoxelMap(double voxel_m);
  // Points in the map frame; non-finite points are left out. Points without colours get
  // kUncolored.
  void add(const PointCloud& cloud);
  // Ordered by voxel, with one colour a point.
  const PointCloud& cloud() const { return cloud_; }
  double voxel_m() const { return voxel_m_; }

  static constexpr Rgb kUncolored{128, 128, 128};

 private:
  double voxel_m_;
  std::vector<std::uint64_t> keys_;  // sorted, parallel to cloud_
  PointCloud cloud_;
};

}  // namespace scanplan
