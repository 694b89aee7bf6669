#include "http/utf8.hpp"

#include <cstdint>

namespace scanplan::http {

std::size_t utf8_sequence_length(std::string_view bytes, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
  const std::size_t left = bytes.size() - at;
  const unsigned char lead = *p;
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  // The allowed range of the second byte is what rules out overlong forms, surrogates and
  // code points above U+10FFFF (RFC 3629 §4, the UTF8-2..UTF8-4 productions).
  unsigned char low = 0x80;
  unsigned char high = 0xBF;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;
    if (lead == 0xED) high = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;
  } else {
    return 0;  // a continuation byte without a lead, C0/C1 (always overlong) or F5..FF
  }
  if (left < length) return 0;
  if (p[1] < low || p[1] > high) return 0;
  for (std::size_t i = 2; i < length; ++i) {
    if ((p[i] & 0xC0) != 0x80) return 0;
  }
  return length;
}

bool is_valid_utf8(std::string_view bytes) {
  for (std::size_t at = 0; at < bytes.size();) {
    const std::size_t n = utf8_sequence_length(bytes, at);
    if (n == 0) return false;
    at += n;
  }
  return true;
}

std::size_t utf8_prefix_length(std::string_view bytes, std::size_t max_bytes) {
  if (bytes.size() <= max_bytes) return bytes.size();
  std::size_t n = max_bytes;
  // Back off over continuation bytes: the cut then falls just before a lead byte.
  while (n > 0 && (static_cast<unsigned char>(bytes[n]) & 0xC0) == 0x80) --n;
  return n;
}

}  // namespace scanplan::http
