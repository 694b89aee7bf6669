#pragma once

// Client-side WebSocket framing for tests, written independently of the server's frame code so
// that a shared misunderstanding of RFC 6455 cannot hide in both.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace scanplan::http::test {

// One frame as a client sends it (RFC 6455 §5.2): masked unless told otherwise, length in the
// shortest encoding.
inline std::string client_frame(std::uint8_t opcode, std::string_view payload, bool fin = true,
                                bool masked = true,
                                std::array<std::uint8_t, 4> key = {0x37, 0xfa, 0x21, 0x3d}) {
  std::string out;
  out.push_back(static_cast<char>((fin ? 0x80 : 0x00) | (opcode & 0x0F)));
  const std::uint8_t mask_bit = masked ? 0x80 : 0x00;
  const std::uint64_t n = payload.size();
  if (n < 126) {
    out.push_back(static_cast<char>(mask_bit | n));
  } else if (n <= 0xFFFF) {
    out.push_back(static_cast<char>(mask_bit | 126));
    out.push_back(static_cast<char>(n >> 8));
    out.push_back(static_cast<char>(n & 0xFF));
  } else {
    out.push_back(static_cast<char>(mask_bit | 127));
    for (int shift = 56; shift >= 0; shift -= 8)
      out.push_back(static_cast<char>((n >> shift) & 0xFF));
  }
  if (masked) {
    for (std::uint8_t k : key) out.push_back(static_cast<char>(k));
  }
  for (std::size_t i = 0; i < payload.size(); ++i) {
    const std::uint8_t m = masked ? key[i % 4] : 0;
    out.push_back(static_cast<char>(static_cast<std::uint8_t>(payload[i]) ^ m));
  }
  return out;
}

// The payload of a close frame: big-endian code, then the reason.
inline std::string close_payload(std::uint16_t code, std::string_view reason = {}) {
  std::string p;
  p.push_back(static_cast<char>(code >> 8));
  p.push_back(static_cast<char>(code & 0xFF));
  p.append(reason);
  return p;
}

// A server frame as the client sees it.
struct ServerFrame {
  bool fin = false;
  std::uint8_t opcode = 0;
  bool masked = false;
  std::string payload;

  std::uint16_t close_code() const {
    if (payload.size() < 2) return 1005;
    return static_cast<std::uint16_t>((static_cast<std::uint8_t>(payload[0]) << 8) |
                                      static_cast<std::uint8_t>(payload[1]));
  }
  std::string close_reason() const { return payload.size() < 2 ? "" : payload.substr(2); }
};

// Decodes one frame from the front of bytes; how many bytes it took, or 0 if incomplete.
inline std::size_t decode_server_frame(std::string_view bytes, ServerFrame& frame) {
  if (bytes.size() < 2) return 0;
  const auto b0 = static_cast<std::uint8_t>(bytes[0]);
  const auto b1 = static_cast<std::uint8_t>(bytes[1]);
  std::size_t at = 2;
  std::uint64_t n = b1 & 0x7F;
  if (n >= 126) {
    const std::size_t len_bytes = n == 126 ? 2 : 8;
    if (bytes.size() < at + len_bytes) return 0;
    n = 0;
    for (std::size_t i = 0; i < len_bytes; ++i)
      n = (n << 8) | static_cast<std::uint8_t>(bytes[at++]);
  }
  std::array<std::uint8_t, 4> key{};
  const bool masked = (b1 & 0x80) != 0;
  if (masked) {
    if (bytes.size() < at + 4) return 0;
    for (auto& k : key) k = static_cast<std::uint8_t>(bytes[at++]);
  }
  if (bytes.size() - at < n) return 0;
  frame.fin = (b0 & 0x80) != 0;
  frame.opcode = b0 & 0x0F;
  frame.masked = masked;
  frame.payload.assign(bytes.substr(at, n));
  if (masked) {
    for (std::size_t i = 0; i < frame.payload.size(); ++i) {
      frame.payload[i] =
          static_cast<char>(static_cast<std::uint8_t>(frame.payload[i]) ^ key[i % 4]);
    }
  }
  return at + n;
}

}  // namespace scanplan::http::test
