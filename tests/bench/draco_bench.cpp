// Draco encoding of a campus map of SCANS scans coloured from their panoramas (the server
// encodes every scan's points and serves the whole map): time and size per point for Draco's
// speed settings, against the raw size of the same points (float32 xyz + uint8 rgb, 15 bytes a
// point). Prints one JSON line.
// Usage: draco_bench [SCANS]
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "scanplan/compression/draco_codec.hpp"
#include "scanplan/mapping/colorizer.hpp"
#include "scanplan/sim/simulated_shot.hpp"
#include "scanplan/sim/world.hpp"

int main(int argc, char** argv) {
  using namespace scanplan;
  const int scans = argc > 1 ? std::stoi(argv[1]) : 10;
  const World world = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  const RayCaster caster(world);
  PointCloud map;
  for (int k = 0; k < scans; ++k) {
    Pose p = world.start;
    p.x = 30 + (k * 37) % 140;
    p.y = 20 + (k * 23) % 120;
    p.z = world.ground_height(p.x, p.y);
    // Coloured from the panorama as the server colours them: the colours weigh in the size.
    auto shot = simulate_shot(caster, world.scanner, p, static_cast<std::uint64_t>(k + 1));
    colorize(shot->cloud, shot->panorama, shot->camera);
    const Eigen::Affine3f T = p.isometry().cast<float>();
    for (std::size_t i = 0; i < shot->cloud.size(); ++i)
      map.push_back(T * shot->cloud.points[i],
                    shot->cloud.has_colors() ? shot->cloud.colors[i] : Rgb{128, 128, 128});
  }
  nlohmann::json out = {{"bench", "draco_campus_map"},
                        {"scans", scans},
                        {"points", map.size()},
                        {"raw_bytes", map.size() * 15}};
  for (const int speed : {5, 7, 10}) {
    DracoOptions o;
    o.encode_speed = o.decode_speed = speed;
    const auto t0 = std::chrono::steady_clock::now();
    const std::string bytes = encode_draco(map, o);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const auto t1 = std::chrono::steady_clock::now();
    const PointCloud back = decode_draco(bytes);
    const double decode_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
    out["speed_" + std::to_string(speed)] = {
        {"encode_ms", ms},
        {"decode_ms", decode_ms},
        {"bytes", bytes.size()},
        {"ns_per_point", ms * 1e6 / static_cast<double>(map.size())},
        {"bytes_per_point", static_cast<double>(bytes.size()) / static_cast<double>(map.size())},
        {"decoded_points", back.size()}};
  }
  std::printf("%s\n", out.dump().c_str());
}
