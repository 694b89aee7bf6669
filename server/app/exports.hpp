#pragma once

#include <string>
#include <vector>

#include "storage/session_store.hpp"

// What leaves the workstation for other teams besides the map itself (DESIGN.md "REST",
// issue 18): the scans' poses and the annotations, in the map frame.
namespace scanplan::server {

// `scan,robot,x,y,z,roll_deg,pitch_deg,yaw_deg,received_at`, one row per scan as `scans` have
// them (metres and degrees; text fields quoted where they need it, RFC 4180).
std::string poses_csv(const std::vector<StoredScan>& scans);

// A GeoJSON FeatureCollection (RFC 7946) of Point features [x, y, z] with the annotation's id,
// kind, text, author and time. The coordinates are the map frame's metres, not longitude and
// latitude: the collection says so in its "scanplan_frame" member.
std::string annotations_geojson(const std::vector<Annotation>& annotations);

}  // namespace scanplan::server
