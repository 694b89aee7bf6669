#include "scanplan/sim/simulated_shot.hpp"

#include "scanplan/sim/panorama_renderer.hpp"

namespace scanplan {

std::optional<SimulatedShot> simulate_shot(const RayCaster& caster, const ScannerConfig& scanner,
                                           const Pose& true_pose, std::uint64_t seed,
                                           const ScanProgressFn& progress) {
  bool aborted = false;
  const ScanProgressFn watch = [&](double fraction) {
    aborted = progress && !progress(fraction);
    return !aborted;
  };
  SimulatedShot shot;
  shot.cloud = simulate_scan(caster, scanner, true_pose, seed, watch);
  if (aborted) return std::nullopt;
  shot.cloud.colors.clear();
  shot.camera = PanoramaCamera::for_scanner(scanner);
  shot.panorama = render_panorama(caster, shot.camera, true_pose);
  return shot;
}

}  // namespace scanplan
