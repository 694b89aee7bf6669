#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "http/response.hpp"

namespace scanplan::http {

struct HubConfig {
  // Largest message a client may send (after reassembly); a larger one closes it with 1009.
  // Clients only send small JSON control messages.
  std::size_t max_message_bytes = 64 * 1024;
  // Upgraded connections beyond this are closed at once with 1013.
  std::size_t max_clients = 256;
  // Unsent text (event) frames one client may have queued. Events are never dropped, so a client
  // that falls this far behind is closed with 1013 and must reconnect and resync over REST.
  std::size_t max_queued_text_bytes = 1 << 20;
  // Unsent binary (map chunk) frames one client may have queued. Past it the oldest chunks not yet
  // started are dropped: they are stale, the client refetches with map.drc?since=ID.
  std::size_t max_queued_binary_bytes = 4 << 20;
  // A ping goes to each client this long after its last pong; one that does not answer within
  // pong_timeout is disconnected, which also frees what was queued for it.
  std::chrono::milliseconds ping_interval{20000};
  std::chrono::milliseconds pong_timeout{20000};
  // SO_SNDBUF for client sockets; 0 keeps the kernel's autotuning. Stale data can also pile up in
  // the kernel's buffer (several MB on loopback) beyond the hub's limits; a small value makes a
  // slow client lose stale chunks sooner instead of receiving them late.
  int send_buffer_bytes = 0;
  // How long a client gets to answer our close frame (and to receive it) before the TCP
  // connection is closed regardless; also bounds how long stop() waits.
  std::chrono::milliseconds close_timeout{2000};
  // Receives operational problems (protocol errors, slow or unresponsive clients). Empty means
  // stderr. Called on any thread with the hub's lock held: it must not call into the hub.
  std::function<void(std::string_view)> log;
  // Receives each text message a client sends, on the hub thread, without the hub's lock held
  // (so it may call broadcast_text or send_text). Must be quick: every client waits for it.
  // Empty ignores client messages. Exceptions are logged.
  std::function<void(std::uint64_t client, std::string_view label, std::string text)> on_message;
};

// Counters for monitoring and tests; a consistent snapshot taken under the hub's lock.
struct HubStats {
  std::size_t clients = 0;
  std::size_t queued_bytes = 0;  // unsent frame bytes over all clients (shared frames per client)
  std::size_t peak_client_queued_bytes = 0;  // the most one client ever had queued
  std::uint64_t binary_frames_dropped = 0;
  std::uint64_t clients_closed_slow = 0;          // text queue over its limit
  std::uint64_t clients_closed_unresponsive = 0;  // no pong in time
};

// Owns the WebSocket connections of /api/v1/events and pushes events to all of them.
//
// One thread of its own runs an epoll loop over the upgraded (non-blocking) sockets plus an
// eventfd that other threads use to wake it, so a slow browser never holds up the HTTP loop or
// the pipeline. Broadcasts are thread-safe: the frame is encoded once, shared by every client's
// queue, and written by the hub thread.
//
// Memory per client is bounded (see max_queued_bytes_per_client): map chunks are dropped when a
// client falls behind, and after a drop the client receives, once it has caught up, the text event
// {"type":"binary_dropped","count":N,"first_id":A,"last_id":B} (ids of the oldest and newest
// dropped chunks). Text events are never dropped; a client too slow for them is closed with
// 1013. Protocol errors close the client with the code RFC 6455 prescribes (1002, 1003 for a
// binary message, 1007, 1009). Writes use MSG_NOSIGNAL, so a vanished client never raises
// SIGPIPE.
class WebSocketHub {
 public:
  // Throws std::runtime_error if the epoll instance or the eventfd cannot be created.
  explicit WebSocketHub(HubConfig config);
  // Calls stop().
  ~WebSocketHub();
  WebSocketHub(const WebSocketHub&) = delete;
  WebSocketHub& operator=(const WebSocketHub&) = delete;

  // Starts the hub thread. Throws std::logic_error if called twice or after stop().
  void start();

  // Sends close 1001 to every client, waits for their replies (at most close_timeout), closes the
  // connections and joins the hub thread. Idempotent. Connections handed over later are closed
  // with 1001 at once. Throws std::logic_error when called on the hub thread (from on_message).
  void stop();

  // The handler for Response::on_upgrade of a 101 answer (see websocket_handshake_response): it
  // takes the socket and the bytes the client sent after its request. label names the client in
  // log messages (e.g. its address and role). The handler keeps the hub's state alive on its own,
  // so calling it after the hub is gone is safe: the socket is then closed with 1001.
  UpgradeHandler adopt(std::string client_label);

  // Queues one text frame (a JSON event) for every client. Thread-safe. Throws
  // std::invalid_argument if json is not valid UTF-8 and std::length_error if its frame exceeds
  // max_queued_text_bytes (it could never be delivered); does nothing while not running.
  void broadcast_text(std::string json);

  // Queues one binary frame [u8 op][u32 id][u64 ns][payload] for every client, little-endian,
  // where ns is the send time (system clock, ns since the Unix epoch) so a client can measure
  // latency. Thread-safe. Throws std::length_error if the frame exceeds max_queued_binary_bytes.
  void broadcast_binary(std::uint8_t op, std::uint32_t id, std::string payload);

  // Queues one text frame for one client (e.g. an answer to its message). Thread-safe. False when
  // that client is gone or closing. Throws like broadcast_text; a client too slow is closed.
  bool send_text(std::uint64_t client, std::string json);

  // Connected clients, including those in their closing handshake.
  std::size_t clients() const;
  HubStats stats() const;

  // The most one client can make the hub hold: both queue limits, the frame being written and
  // the few control frames that jump the queue.
  std::size_t max_queued_bytes_per_client() const;

 private:
  class Impl;
  std::shared_ptr<Impl> impl_;  // shared with the adopt() handlers, see there
};

}  // namespace scanplan::http
