#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

struct DracoOptions {
  // Position quantisation spans the cloud's largest extent: 14 bits over a 200 m campus is
  // about 1.2 cm, finer than the scanner's own 1 cm noise is worth.
  int position_bits = 14;
  // Draco's 0 (best compression) .. 10 (fastest). For our coloured point clouds 10 is both
  // the fastest and the smallest: 1.8× faster than Draco's default 5 and 18% smaller
  // (tests/bench/draco_bench, docs/benchmarks.md).
  int encode_speed = 10;
  int decode_speed = 10;
};

class DracoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Positions as float32 and, when the cloud has them, colours as normalised uint8 so that
// three.js's DRACOLoader hands the page 0..1 colours without conversion.
std::string encode_draco(const PointCloud& cloud, const DracoOptions& options = {});
// The clouds one after the other as one Draco point cloud, without first copying them into one
// (the whole map of a session: hundreds of megabytes); colours only when every part that has
// points has them.
std::string encode_draco(const std::vector<const PointCloud*>& parts,
                         const DracoOptions& options = {});
PointCloud decode_draco(std::string_view bytes);

}  // namespace scanplan
