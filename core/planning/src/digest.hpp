#pragma once

#include <bit>
#include <cstdint>

namespace scanplan::digest {

// SplitMix64's finaliser over a running digest: cheap, and every input bit reaches every output
// bit. For telling whether what a computation read is the same as before (GainMemo), where two
// different inputs meeting on one 64-bit digest is as likely as a cosmic ray.
inline std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  std::uint64_t z = h ^ (v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2));
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
inline std::uint64_t mix(std::uint64_t h, float v) {
  return mix(h, static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(v)));
}
inline std::uint64_t mix(std::uint64_t h, double v) {
  return mix(h, std::bit_cast<std::uint64_t>(v));
}

}  // namespace scanplan::digest
