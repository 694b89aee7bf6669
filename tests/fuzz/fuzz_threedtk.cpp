// The 3DTK text formats a replay reads (core/io threedtk): scans, .pose and .reference files.
#include <cstdint>
#include <string_view>

#include "scanplan/io/scan_file.hpp"
#include "scanplan/io/threedtk.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)scanplan::parse_threedtk_scan(text, "fuzz");
  } catch (const scanplan::ScanFileError&) {
  }
  try {
    (void)scanplan::parse_threedtk_pose(text, "fuzz");
  } catch (const scanplan::ScanFileError&) {
  }
  try {
    (void)scanplan::parse_threedtk_reference(text, "fuzz");
  } catch (const scanplan::ScanFileError&) {
  }
  return 0;
}
