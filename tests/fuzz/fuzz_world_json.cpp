// World files (core/sim parse_world): any text gives a world or a WorldError naming the problem.
#include <cstdint>
#include <string>

#include "scanplan/sim/world.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)scanplan::parse_world(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
  } catch (const scanplan::WorldError&) {
  }
  return 0;
}
