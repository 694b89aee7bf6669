#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace scanplan::http {

// Frame opcodes (RFC 6455 §5.2). The other values are reserved and fail the connection.
enum class WebSocketOpcode : std::uint8_t {
  kContinuation = 0x0,
  kText = 0x1,
  kBinary = 0x2,
  kClose = 0x8,
  kPing = 0x9,
  kPong = 0xA,
};

// Close status codes (RFC 6455 §7.4.1 and the IANA registry) that this server sends or expects.
namespace websocket_close {
inline constexpr std::uint16_t kNormal = 1000;
inline constexpr std::uint16_t kGoingAway = 1001;  // server shutting down
inline constexpr std::uint16_t kProtocolError = 1002;
inline constexpr std::uint16_t kUnsupportedData = 1003;  // e.g. binary sent to a text-only endpoint
inline constexpr std::uint16_t kNoStatus = 1005;        // never sent: "the close frame had no code"
inline constexpr std::uint16_t kInvalidPayload = 1007;  // text that is not UTF-8
inline constexpr std::uint16_t kPolicyViolation = 1008;
inline constexpr std::uint16_t kMessageTooBig = 1009;
inline constexpr std::uint16_t kInternalError = 1011;
inline constexpr std::uint16_t kTryAgainLater =
    1013;  // overloaded, e.g. a client reading too slowly
}  // namespace websocket_close

// Control frames carry at most this much payload and are never fragmented (RFC 6455 §5.5).
inline constexpr std::size_t kMaxControlPayload = 125;

// Whether a peer may put code in a close frame: the codes defined for use on the wire plus the
// ranges for libraries (3000-3999) and applications (4000-4999). 1005 and 1006 only exist inside
// APIs, to say that no code arrived.
bool is_valid_close_code(std::uint16_t code);

// One message received from the peer: a whole (reassembled) data message or one control frame.
struct WebSocketMessage {
  WebSocketOpcode opcode = WebSocketOpcode::kText;  // never kContinuation
  std::string payload;           // for kClose: only the reason text (valid UTF-8), without the code
  std::uint16_t close_code = 0;  // for kClose: the code received, or kNoStatus when there was none
};

// Who sent the frames a parser reads. Client frames must be masked and server frames must not
// be (RFC 6455 §5.1); the server's hub reads client frames, the CLI's `watch` reads server frames.
enum class WebSocketFrameSender { kClient, kServer };

// Incremental parser for WebSocket frames (RFC 6455 §5): by default those a client sends to a
// server; with WebSocketFrameSender::kServer, those a server sends to a client.
//
// Bytes arrive in arbitrary pieces; feed() stops after each complete message so the caller can
// take() it, then feeds the rest again, as with RequestParser. Fragmented data messages are
// reassembled; control frames may arrive between their fragments and are delivered on their own.
// A message larger than max_message_bytes is refused from its frame header alone, before its
// payload is buffered. No extension is negotiated, so the RSV bits must be zero.
//
// Errors carry the close code to fail the connection with: 1002 for a protocol violation (a
// frame masked the wrong way for its sender, a reserved opcode or bit, a fragmented or oversized
// control frame, a stray or missing continuation, a malformed close frame), 1007 for text that is
// not UTF-8 and 1009 for a message over the limit. After an error the stream cannot be
// resynchronised.
class WebSocketFrameParser {
 public:
  enum class State { kIncomplete, kComplete, kError };

  explicit WebSocketFrameParser(std::size_t max_message_bytes,
                                WebSocketFrameSender sender = WebSocketFrameSender::kClient);

  // Consumes a prefix of data and returns its length. Stops early when a message is complete
  // (state kComplete) or at an error (state kError); consumes nothing in those states.
  std::size_t feed(std::string_view data);

  State state() const { return state_; }

  // Moves out the complete message. A data message being reassembled around a control frame is
  // kept. Throws std::logic_error unless state() is kComplete.
  WebSocketMessage take();

  std::uint16_t error_code() const { return error_code_; }
  const std::string& error_message() const { return error_message_; }

  // Bytes of an unfinished data message held so far; bounded by max_message_bytes.
  std::size_t buffered_bytes() const { return message_.size(); }

 private:
  bool fail(std::uint16_t code, std::string message);
  bool on_header();
  bool on_frame_end();

  std::size_t max_message_bytes_;
  bool masked_;  // whether frames must carry a mask (client frames) or must not (server frames)
  State state_ = State::kIncomplete;
  std::array<unsigned char, 14> header_{};  // 2 fixed + up to 8 length + 4 mask bytes
  std::size_t header_size_ = 0;
  bool in_payload_ = false;

  // The frame whose payload is arriving.
  WebSocketOpcode frame_opcode_ = WebSocketOpcode::kContinuation;
  bool frame_fin_ = false;
  std::array<unsigned char, 4> mask_{};
  std::uint64_t frame_offset_ = 0;  // payload bytes of the frame received so far (mask phase)
  std::uint64_t remaining_ = 0;     // payload bytes of the frame still to come

  bool in_message_ = false;  // a fragmented data message awaits continuation frames
  WebSocketOpcode message_opcode_ = WebSocketOpcode::kText;
  std::string message_;
  std::string control_;  // the payload of a control frame, kept apart from message_
  WebSocketMessage ready_;

  std::uint16_t error_code_ = 0;
  std::string error_message_;
};

// Writes server frames: unmasked (RFC 6455 §5.1 forbids masking from servers), unfragmented, with
// the shortest length encoding. Control payloads over kMaxControlPayload throw
// std::invalid_argument, as does kContinuation.
std::string encode_websocket_frame(WebSocketOpcode opcode, std::string_view payload);

// Appends only the header of such a frame, for building a frame whose payload is assembled in
// place (saves copying a large payload a second time).
void append_websocket_frame_header(std::string& out, WebSocketOpcode opcode,
                                   std::uint64_t payload_bytes);

// A close frame with code and reason. The reason is shortened at a character boundary to fit the
// control-frame limit, and left out if it is not valid UTF-8 (the peer would fail the connection
// over it); a code that may not appear on the wire (see is_valid_close_code) throws
// std::invalid_argument.
std::string encode_websocket_close(std::uint16_t code, std::string_view reason);

}  // namespace scanplan::http
