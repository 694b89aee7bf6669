#include "http/websocket_frame.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "http/utf8.hpp"

namespace scanplan::http {
namespace {

constexpr unsigned char kFin = 0x80;
constexpr unsigned char kRsvBits = 0x70;
constexpr unsigned char kOpcodeBits = 0x0F;
constexpr unsigned char kMaskBit = 0x80;
constexpr unsigned char kLengthBits = 0x7F;
constexpr unsigned char kLength16 = 126;
constexpr unsigned char kLength64 = 127;
// Reserving a client's announced length up front would let it make us allocate memory it never
// sends; beyond this the string grows as bytes actually arrive.
constexpr std::size_t kMaxReserve = 64 * 1024;

bool is_control(WebSocketOpcode opcode) {
  return (static_cast<unsigned>(opcode) & 0x8) != 0;
}

bool is_known(unsigned value) {
  switch (static_cast<WebSocketOpcode>(value)) {
    case WebSocketOpcode::kContinuation:
    case WebSocketOpcode::kText:
    case WebSocketOpcode::kBinary:
    case WebSocketOpcode::kClose:
    case WebSocketOpcode::kPing:
    case WebSocketOpcode::kPong:
      return true;
  }
  return false;
}

std::string bytes_text(std::uint64_t n) {
  return std::to_string(n) + " bytes";
}

}  // namespace

bool is_valid_close_code(std::uint16_t code) {
  if (code >= 3000 && code <= 4999) return true;
  return (code >= 1000 && code <= 1003) || (code >= 1007 && code <= 1014);
}

WebSocketFrameParser::WebSocketFrameParser(std::size_t max_message_bytes,
                                           WebSocketFrameSender sender)
    : max_message_bytes_(max_message_bytes), masked_(sender == WebSocketFrameSender::kClient) {}

bool WebSocketFrameParser::fail(std::uint16_t code, std::string message) {
  state_ = State::kError;
  error_code_ = code;
  error_message_ = std::move(message);
  message_.clear();
  message_.shrink_to_fit();
  return false;
}

WebSocketMessage WebSocketFrameParser::take() {
  if (state_ != State::kComplete) {
    throw std::logic_error("WebSocketFrameParser::take() called before a message was complete");
  }
  state_ = State::kIncomplete;
  return std::exchange(ready_, WebSocketMessage{});
}

std::size_t WebSocketFrameParser::feed(std::string_view data) {
  std::size_t pos = 0;
  while (state_ == State::kIncomplete && pos < data.size()) {
    if (!in_payload_) {
      // The header is 2..14 bytes and its size is known only after its second byte, so it is
      // gathered a byte at a time; that is a few bytes per frame.
      header_[header_size_++] = static_cast<unsigned char>(data[pos++]);
      if (header_size_ < 2) continue;
      const unsigned char length_bits = header_[1] & kLengthBits;
      const std::size_t length_bytes =
          length_bits == kLength64 ? 8 : (length_bits == kLength16 ? 2 : 0);
      // Checked before the rest arrives so that a wrongly masked frame fails at once.
      if (header_size_ == 2 && ((header_[1] & kMaskBit) != 0) != masked_) {
        fail(websocket_close::kProtocolError,
             masked_ ? "client frames must be masked (RFC 6455 §5.1); this frame is not"
                     : "server frames must not be masked (RFC 6455 §5.1); this frame is");
        break;
      }
      if (header_size_ < 2 + length_bytes + (masked_ ? 4 : 0)) continue;
      if (!on_header()) break;
      if (remaining_ == 0) on_frame_end();
      continue;
    }

    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, data.size() - pos));
    std::string& sink = is_control(frame_opcode_) ? control_ : message_;
    const std::size_t start = sink.size();
    sink.append(data.data() + pos, n);
    for (std::size_t i = 0; masked_ && i < n; ++i) {
      sink[start + i] = static_cast<char>(static_cast<unsigned char>(sink[start + i]) ^
                                          mask_[(frame_offset_ + i) & 3]);
    }
    pos += n;
    frame_offset_ += n;
    remaining_ -= n;
    if (remaining_ == 0) on_frame_end();
  }
  return pos;
}

bool WebSocketFrameParser::on_header() {
  const unsigned char b0 = header_[0];
  const unsigned char b1 = header_[1];
  if ((b0 & kRsvBits) != 0) {
    return fail(websocket_close::kProtocolError,
                "reserved bits RSV1-3 are set, but no extension was negotiated");
  }
  const unsigned opcode_value = b0 & kOpcodeBits;
  if (!is_known(opcode_value)) {
    return fail(websocket_close::kProtocolError,
                "reserved opcode 0x" + std::string(1, "0123456789abcdef"[opcode_value]));
  }
  const auto opcode = static_cast<WebSocketOpcode>(opcode_value);
  const bool fin = (b0 & kFin) != 0;

  std::uint64_t length = b1 & kLengthBits;
  std::size_t at = 2;
  if (length == kLength16 || length == kLength64) {
    const std::size_t bytes = length == kLength16 ? 2 : 8;
    length = 0;
    for (std::size_t i = 0; i < bytes; ++i) length = (length << 8) | header_[at++];
    if (bytes == 8 && (length >> 63) != 0) {
      return fail(websocket_close::kProtocolError,
                  "64-bit payload length has its most significant bit set (RFC 6455 §5.2)");
    }
  }
  if (masked_) std::copy_n(header_.begin() + static_cast<std::ptrdiff_t>(at), 4, mask_.begin());

  if (is_control(opcode)) {
    if (!fin) return fail(websocket_close::kProtocolError, "control frames must not be fragmented");
    if (length > kMaxControlPayload) {
      return fail(websocket_close::kProtocolError,
                  "control frame payload of " + bytes_text(length) + " exceeds the limit of " +
                      bytes_text(kMaxControlPayload));
    }
    control_.clear();
  } else if (opcode == WebSocketOpcode::kContinuation) {
    if (!in_message_) {
      return fail(websocket_close::kProtocolError,
                  "continuation frame without a fragmented message to continue");
    }
  } else {
    if (in_message_) {
      return fail(websocket_close::kProtocolError,
                  "new data message started before the fragmented one was finished");
    }
    in_message_ = true;
    message_opcode_ = opcode;
    message_.clear();
  }
  if (!is_control(opcode)) {
    // Checked against the header alone, so an oversized message is refused before it is buffered.
    if (length > max_message_bytes_ - std::min<std::size_t>(message_.size(), max_message_bytes_)) {
      return fail(websocket_close::kMessageTooBig,
                  "message exceeds the limit of " + bytes_text(max_message_bytes_));
    }
    message_.reserve(message_.size() +
                     static_cast<std::size_t>(std::min<std::uint64_t>(length, kMaxReserve)));
  }

  frame_opcode_ = opcode;
  frame_fin_ = fin;
  frame_offset_ = 0;
  remaining_ = length;
  header_size_ = 0;
  in_payload_ = true;
  return true;
}

bool WebSocketFrameParser::on_frame_end() {
  in_payload_ = false;
  if (is_control(frame_opcode_)) {
    ready_ = WebSocketMessage{};
    ready_.opcode = frame_opcode_;
    if (frame_opcode_ == WebSocketOpcode::kClose) {
      if (control_.size() == 1) {
        return fail(websocket_close::kProtocolError,
                    "close frame payload of 1 byte: a close code takes 2 bytes");
      }
      if (control_.empty()) {
        ready_.close_code = websocket_close::kNoStatus;
      } else {
        const auto code =
            static_cast<std::uint16_t>((static_cast<unsigned char>(control_[0]) << 8) |
                                       static_cast<unsigned char>(control_[1]));
        if (!is_valid_close_code(code)) {
          return fail(websocket_close::kProtocolError,
                      "close code " + std::to_string(code) + " may not be sent on the wire");
        }
        if (!is_valid_utf8(std::string_view(control_).substr(2))) {
          return fail(websocket_close::kInvalidPayload, "close reason is not valid UTF-8");
        }
        ready_.close_code = code;
        control_.erase(0, 2);
      }
    }
    ready_.payload = std::move(control_);
    control_.clear();
    state_ = State::kComplete;
    return true;
  }

  if (!frame_fin_) return true;  // more fragments follow
  in_message_ = false;
  if (message_opcode_ == WebSocketOpcode::kText && !is_valid_utf8(message_)) {
    return fail(websocket_close::kInvalidPayload, "text message is not valid UTF-8");
  }
  ready_ = WebSocketMessage{};
  ready_.opcode = message_opcode_;
  ready_.payload = std::move(message_);
  message_.clear();
  state_ = State::kComplete;
  return true;
}

void append_websocket_frame_header(std::string& out, WebSocketOpcode opcode,
                                   std::uint64_t payload_bytes) {
  if (opcode == WebSocketOpcode::kContinuation) {
    throw std::invalid_argument("server frames are never fragmented; kContinuation is not used");
  }
  if (is_control(opcode) && payload_bytes > kMaxControlPayload) {
    throw std::invalid_argument("control frame payload of " + bytes_text(payload_bytes) +
                                " exceeds the limit of " + bytes_text(kMaxControlPayload));
  }
  out.push_back(static_cast<char>(kFin | static_cast<unsigned char>(opcode)));
  if (payload_bytes < kLength16) {
    out.push_back(static_cast<char>(payload_bytes));
  } else if (payload_bytes <= 0xFFFF) {
    out.push_back(static_cast<char>(kLength16));
    out.push_back(static_cast<char>(payload_bytes >> 8));
    out.push_back(static_cast<char>(payload_bytes & 0xFF));
  } else {
    out.push_back(static_cast<char>(kLength64));
    for (int shift = 56; shift >= 0; shift -= 8) {
      out.push_back(static_cast<char>((payload_bytes >> shift) & 0xFF));
    }
  }
}

std::string encode_websocket_frame(WebSocketOpcode opcode, std::string_view payload) {
  std::string out;
  out.reserve(10 + payload.size());
  append_websocket_frame_header(out, opcode, payload.size());
  out.append(payload);
  return out;
}

std::string encode_websocket_close(std::uint16_t code, std::string_view reason) {
  if (!is_valid_close_code(code)) {
    throw std::invalid_argument("close code " + std::to_string(code) +
                                " may not be sent on the wire");
  }
  if (!is_valid_utf8(reason)) reason = {};
  reason = reason.substr(0, utf8_prefix_length(reason, kMaxControlPayload - 2));
  std::string payload;
  payload.reserve(2 + reason.size());
  payload.push_back(static_cast<char>(code >> 8));
  payload.push_back(static_cast<char>(code & 0xFF));
  payload.append(reason);
  return encode_websocket_frame(WebSocketOpcode::kClose, payload);
}

}  // namespace scanplan::http
