#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "http/unique_fd.hpp"
#include "http/websocket_frame.hpp"

namespace scanplan::http {

// One encoded server frame waiting to be written. Broadcast frames are shared by every client's
// queue, so a map chunk costs its size once however many clients there are.
struct OutgoingFrame {
  enum class Kind : std::uint8_t { kText, kBinary, kPing, kPong, kClose };

  std::shared_ptr<const std::string> bytes;
  Kind kind = Kind::kText;
  std::uint32_t chunk_id = 0;  // for kBinary: reported to the client when the chunk is dropped
};

// The state WebSocketHub keeps for one upgraded socket. Plain data: the hub owns the logic, so
// that every transition is visible in one place (as with Connection and HttpServer).
struct WebSocketConnection {
  using Clock = std::chrono::steady_clock;

  WebSocketConnection(std::uint64_t id_, UniqueFd fd_, std::string label_,
                      std::size_t max_message_bytes)
      : id(id_), fd(std::move(fd_)), label(std::move(label_)), parser(max_message_bytes) {}

  bool has_output() const { return sending.has_value() || !control.empty() || !data.empty(); }

  // Bytes held for this client: queued frames plus the unsent rest of the frame being written.
  std::size_t queued_bytes() const {
    const std::size_t in_flight = sending ? sending->bytes->size() - sending_offset : 0;
    return queued_text + queued_binary + queued_control + in_flight;
  }

  std::uint64_t id;
  UniqueFd fd;
  std::string label;
  WebSocketFrameParser parser;
  std::string early_input;  // sent right after the handshake; parsed once on the hub thread

  // Control frames go before data at the next frame boundary, so pings, pongs and the close
  // frame are not stuck behind megabytes of map chunks. Frames in these queues are not started,
  // so any of them may still be dropped.
  std::deque<OutgoingFrame> control;
  std::deque<OutgoingFrame> data;
  std::optional<OutgoingFrame> sending;  // partly written: must be finished before anything else
  std::size_t sending_offset = 0;
  std::size_t queued_text = 0;  // bytes in data by kind
  std::size_t queued_binary = 0;
  std::size_t queued_control = 0;

  // Chunks dropped since the client was last told (see WebSocketHub).
  std::uint64_t dropped = 0;
  std::uint32_t first_dropped_id = 0;
  std::uint32_t last_dropped_id = 0;

  bool awaiting_pong = false;
  Clock::time_point ping_sent;
  Clock::time_point next_ping;

  bool close_queued = false;    // our close frame is queued or sent: nothing else follows it
  bool close_sent = false;      // ... and fully written
  bool close_received = false;  // the client's close frame arrived
  bool failing = false;         // protocol error: no close reply is awaited, only the client's EOF
  std::size_t discarded_bytes = 0;  // input read and ignored after our close frame went out
  Clock::time_point close_deadline;

  bool dirty = false;        // in the hub's list of clients with work from other threads
  std::uint32_t events = 0;  // the epoll interest currently registered
};

}  // namespace scanplan::http
