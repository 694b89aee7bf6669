#include "text_fields.hpp"

#include <algorithm>

namespace scanplan {
namespace {

constexpr std::size_t kMaxRobotIdBytes = 64;

// Length of the UTF-8 sequence starting at text[i], 0 when it is not a valid one (overlong
// forms, surrogates and code points beyond U+10FFFF included).
std::size_t utf8_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned lo = 0x80, hi = 0xBF;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (i + n > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return n;
}

// 'field', built by appending (GCC 12 warns of a false overlap in "'" + string + "'").
std::string quoted(std::string_view field) {
  std::string out;
  out.reserve(field.size() + 2);
  out += '\'';
  out.append(field);
  out += '\'';
  return out;
}

}  // namespace

std::optional<std::string> robot_id_problem(std::string_view text, std::string_view field) {
  const bool allowed = std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
  if (!text.empty() && text.size() <= kMaxRobotIdBytes && allowed) return std::nullopt;
  return quoted(field) + " must be 1 to " + std::to_string(kMaxRobotIdBytes) +
         " characters of A-Z, a-z, 0-9, '_', '-' and '.'";
}

std::optional<std::string> text_problem(std::string_view text, std::string_view field,
                                        std::size_t max_bytes, TextKind kind) {
  const std::string name = quoted(field);
  if (text.size() > max_bytes) {
    return name + " is too long: " + std::to_string(text.size()) + " bytes, at most " +
           std::to_string(max_bytes);
  }
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_length(text, i);
    if (n == 0) return name + " is not valid UTF-8";
    const auto c = static_cast<unsigned char>(text[i]);
    const bool control = n == 1 && (c < 0x20 || c == 0x7F);
    const bool prose_space = kind == TextKind::kProse && (c == '\n' || c == '\t' || c == '\r');
    if (control && !prose_space) {
      return name + (kind == TextKind::kLine ? " must be one line without control characters"
                                             : " must not hold control characters");
    }
    i += n;
  }
  return std::nullopt;
}

}  // namespace scanplan
