#pragma once

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace scanplan::test {

// The DDS domain id ctest gave this test (SCANPLAN_TEST_DOMAIN, from the one allocator in
// tests/CMakeLists.txt): no two tests that may run at once share one.
inline std::uint32_t test_domain() {
  const char* value = std::getenv("SCANPLAN_TEST_DOMAIN");
  if (value == nullptr || *value == '\0') {
    throw std::runtime_error(
        "SCANPLAN_TEST_DOMAIN is not set: run this test through ctest, or set it to a DDS domain "
        "id no other test uses");
  }
  const unsigned long id = std::stoul(value);
  // Cyclone's default port mapping (7400 + 250·id + offsets) runs out of ports above 232.
  if (id > 232) throw std::runtime_error("SCANPLAN_TEST_DOMAIN " + std::string(value) + " > 232");
  return static_cast<std::uint32_t>(id);
}

}  // namespace scanplan::test
