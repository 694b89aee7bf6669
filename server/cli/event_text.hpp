#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace scanplan::cli {

// A binary frame of GET /api/v1/events: [u8 op][u32 id][u64 ns][payload], little-endian;
// op 1 is a new scan's points as Draco, id the scan.
struct MapChunk {
  std::uint8_t op = 0;
  std::uint32_t id = 0;
  std::uint64_t sent_ns = 0;  // send time, nanoseconds since the epoch
  std::size_t payload_bytes = 0;
};

// nullopt when the frame is shorter than its 13-byte header.
std::optional<MapChunk> parse_map_chunk(std::string_view frame);

// What an event says, in a line for the terminal (without the time and type columns, which the
// printer adds): e.g. for match_done "scan 2: ndt-icp converged, score 123.4, rmse 0.045 m,
// correction dx +0.31 dy -0.12 dz +0.01 m dyaw +1.2 deg (applied), 350 ms". Types this client
// does not know are shown as their JSON, so nothing the server says is hidden.
std::string describe_event(const nlohmann::json& event);

// "scan 2 map chunk: 1234567 bytes of Draco (not shown)".
std::string describe_map_chunk(const MapChunk& chunk);

// The chunk as a JSON line for --json: {"type":"map_chunk","op","scan","bytes","sent_ns"}.
nlohmann::json map_chunk_json(const MapChunk& chunk);

}  // namespace scanplan::cli
