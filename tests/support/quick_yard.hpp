#pragma once

#include "scanplan/sim/simulated_scanner.hpp"
#include "scanplan/sim/world.hpp"

namespace scanplan::testing_support {

// The yard world scanned at 1° stage steps (a quarter of the points: quick, still matchable),
// made once for every test that scans it.
inline const World& quick_yard() {
  static const World world = [] {
    World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json");
    w.scanner.rotation_step_deg = 1.0;
    return w;
  }();
  return world;
}

// A scan of the quick yard taken at `truth`, its noise drawn from `seed`.
inline PointCloud quick_yard_scan(const Pose& truth, std::uint64_t seed) {
  static const RayCaster caster(quick_yard());
  return simulate_scan(caster, quick_yard().scanner, truth, seed);
}

}  // namespace scanplan::testing_support
