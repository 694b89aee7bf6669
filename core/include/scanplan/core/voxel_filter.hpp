#pragma once

#include "scanplan/core/point_cloud.hpp"

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

}  // namespace scanplan
