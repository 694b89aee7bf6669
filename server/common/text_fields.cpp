#include "text_fields.hpp"

#include <algorithm>

#include "http/utf8.hpp"

namespace scanplan {
namespace {

constexpr std::size_t kMaxRobotIdBytes = 64;

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

std::string cleaned_text(std::string_view text, std::size_t max_bytes) {
  static constexpr std::string_view kReplacement = "\xEF\xBF\xBD";
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = http::utf8_sequence_length(text, i);
    std::string_view piece = n == 0 ? kReplacement : text.substr(i, n);
    if (n == 1) {
      const auto c = static_cast<unsigned char>(text[i]);
      if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7F) piece = " ";
    }
    if (out.size() + piece.size() > max_bytes) break;
    out += piece;
    i += n == 0 ? 1 : n;
  }
  return out;
}

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
    const std::size_t n = http::utf8_sequence_length(text, i);
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
