// The PLY reader a client's upload goes through (core/io read_ply_bytes): any bytes give a cloud
// or a ScanFileError, never a crash, and no allocation the bytes do not pay for (a header that
// announces a billion vertices is refused from its size).
#include <cstdint>
#include <string_view>

#include "scanplan/io/ply_io.hpp"
#include "scanplan/io/scan_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)scanplan::read_ply_bytes(std::string_view(reinterpret_cast<const char*>(data), size),
                                   "fuzz");
  } catch (const scanplan::ScanFileError&) {
  }
  return 0;
}
