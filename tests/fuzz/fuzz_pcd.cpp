// The PCD reader (core/io read_pcd_bytes), as fuzz_ply.
#include <cstdint>
#include <string_view>

#include "scanplan/io/pcd_io.hpp"
#include "scanplan/io/scan_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)scanplan::read_pcd_bytes(std::string_view(reinterpret_cast<const char*>(data), size),
                                   "fuzz");
  } catch (const scanplan::ScanFileError&) {
  }
  return 0;
}
