#include "http/websocket_hub.hpp"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "http/unique_fd.hpp"
#include "http/utf8.hpp"
#include "http/websocket_connection.hpp"
#include "http/websocket_frame.hpp"

namespace scanplan::http {
namespace {

using Clock = std::chrono::steady_clock;
using Kind = OutgoingFrame::Kind;

// epoll user data for the eventfd; client ids start above it.
constexpr std::uint64_t kWakeId = 0;
constexpr std::size_t kReadBufferBytes = 64 * 1024;
// Reads per readiness event, so one chatty client cannot starve the others.
constexpr int kReadsPerEvent = 4;
// After our close frame a client gets this much more input read and ignored before the socket
// is closed regardless; enough for whatever it had in flight.
constexpr std::size_t kMaxDiscardBytes = 1 << 20;
// Upper bound on how long epoll_wait sleeps, so deadlines are checked regularly.
constexpr std::chrono::milliseconds kMaxSweepInterval{1000};
// [u8 op][u32 id][u64 ns] in front of every map chunk.
constexpr std::size_t kBinaryPrefixBytes = 1 + 4 + 8;
// Frame header bytes in front of a payload of any size.
constexpr std::size_t kMaxFrameHeaderBytes = 10;
// The control frames a client can have queued at once: a ping, one pong (a newer ping replaces
// an unanswered one) and the close frame, each at most a full control frame.
constexpr std::size_t kControlSlack = 3 * (2 + kMaxControlPayload);

std::string errno_text(int err) {
  return std::generic_category().message(err);
}

void append_le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

// Sends a close frame to a socket the hub will not keep, without waiting: a fresh socket has
// room for a few bytes, and if not, the client learns from the TCP close anyway.
void refuse(UniqueFd fd, std::uint16_t code, std::string_view reason) {
  const std::string frame = encode_websocket_close(code, reason);
  [[maybe_unused]] const ssize_t n =
      ::send(fd.get(), frame.data(), frame.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

void validate(const HubConfig& config) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("HubConfig: ") + what);
  };
  require(config.max_message_bytes > 0, "max_message_bytes must be positive");
  require(config.max_clients > 0, "max_clients must be positive");
  require(config.max_queued_text_bytes >= 1024,
          "max_queued_text_bytes must be at least 1024 so small events fit");
  require(config.max_queued_binary_bytes >= 1024,
          "max_queued_binary_bytes must be at least 1024 so small chunks fit");
  require(config.ping_interval.count() > 0, "ping_interval must be positive");
  require(config.pong_timeout.count() > 0, "pong_timeout must be positive");
  require(config.close_timeout.count() > 0, "close_timeout must be positive");
  require(config.send_buffer_bytes >= 0, "send_buffer_bytes must not be negative");
}

}  // namespace

// Everything behind the public interface, shared with the adopt() handlers so that a handler
// outliving the hub finds a stopped hub rather than freed memory.
//
// One mutex guards all state. The hub thread holds it while it handles a batch of events (every
// socket call is non-blocking, so that is short) and releases it before calling on_message;
// broadcasting threads hold it while they append to the queues. Only the hub thread writes to
// and reads from the sockets.
class WebSocketHub::Impl {
 public:
  explicit Impl(HubConfig config) : config_(std::move(config)), read_buffer_(kReadBufferBytes) {
    validate(config_);
    wake_.reset(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
    if (!wake_) {
      throw std::runtime_error("WebSocket hub: cannot create eventfd: " + errno_text(errno));
    }
    epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
    if (!epoll_) {
      throw std::runtime_error("WebSocket hub: epoll_create1 failed: " + errno_text(errno));
    }
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = kWakeId;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, wake_.get(), &ev) != 0) {
      throw std::runtime_error("WebSocket hub: epoll_ctl failed: " + errno_text(errno));
    }
  }

  const HubConfig& config() const { return config_; }

  void start() {
    const std::lock_guard lock(mutex_);
    if (phase_ != Phase::kCreated) {
      throw std::logic_error("WebSocketHub::start() called twice or after stop()");
    }
    phase_ = Phase::kRunning;
    thread_ = std::thread([this] { run(); });
    thread_id_ = thread_.get_id();
  }

  void stop() {
    {
      const std::lock_guard lock(mutex_);
      if (thread_id_ == std::this_thread::get_id()) {
        throw std::logic_error(
            "WebSocketHub::stop() called on the hub thread (from on_message); it would wait for "
            "itself");
      }
      if (phase_ == Phase::kCreated) phase_ = Phase::kStopped;
      if (phase_ == Phase::kRunning) phase_ = Phase::kStopping;
    }
    wake();
    const std::lock_guard join_lock(join_mutex_);
    if (thread_.joinable()) thread_.join();
    const std::lock_guard lock(mutex_);
    thread_id_ = {};  // ids of finished threads are reused
  }

  void adopt(int raw_fd, const std::string& label, std::string buffered) {
    UniqueFd fd(raw_fd);
    // The hub thread must never block on one client; the contract says non-blocking, make sure.
    const int flags = ::fcntl(fd.get(), F_GETFL);
    if (flags < 0 || ::fcntl(fd.get(), F_SETFL, flags | O_NONBLOCK) != 0) {
      const int err = errno;
      const std::lock_guard lock(mutex_);
      log("websocket: cannot make the socket of " + label + " non-blocking: " + errno_text(err));
      return;
    }
    if (config_.send_buffer_bytes > 0) {
      // Best effort: the kernel clamps the value and a failure only means more buffering.
      ::setsockopt(fd.get(), SOL_SOCKET, SO_SNDBUF, &config_.send_buffer_bytes,
                   sizeof(config_.send_buffer_bytes));
    }
    const std::lock_guard lock(mutex_);
    if (phase_ != Phase::kRunning) {
      refuse(std::move(fd), websocket_close::kGoingAway, "the event hub is not running");
      return;
    }
    if (live_clients_ >= config_.max_clients) {
      log("websocket: refusing " + label + ": already " + std::to_string(live_clients_) +
          " clients (max_clients)");
      refuse(std::move(fd), websocket_close::kTryAgainLater, "too many clients; retry later");
      return;
    }
    const std::uint64_t id = next_id_++;
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLRDHUP;
    ev.data.u64 = id;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd.get(), &ev) != 0) {
      log("websocket: cannot watch the socket of " + label + ": " + errno_text(errno));
      return;
    }
    auto client =
        std::make_unique<WebSocketConnection>(id, std::move(fd), label, config_.max_message_bytes);
    client->events = ev.events;
    client->early_input = std::move(buffered);
    client->next_ping = Clock::now() + config_.ping_interval;
    schedule(client->next_ping);
    WebSocketConnection& c = *clients_.emplace(id, std::move(client)).first->second;
    ++live_clients_;
    mark_dirty(c);
  }

  void broadcast(const OutgoingFrame& frame) {
    const std::lock_guard lock(mutex_);
    if (phase_ != Phase::kRunning) return;
    const Clock::time_point now = Clock::now();
    for (auto& [id, c] : clients_) {
      if (c->fd) enqueue(*c, frame, now);
    }
  }

  bool send_to(std::uint64_t client, const OutgoingFrame& frame) {
    const std::lock_guard lock(mutex_);
    if (phase_ != Phase::kRunning) return false;
    const auto it = clients_.find(client);
    if (it == clients_.end() || !it->second->fd || it->second->close_queued) return false;
    enqueue(*it->second, frame, Clock::now());
    return !it->second->close_queued;
  }

  std::size_t clients() const {
    const std::lock_guard lock(mutex_);
    return live_clients_;
  }

  HubStats stats() const {
    const std::lock_guard lock(mutex_);
    HubStats s = stats_;
    s.clients = live_clients_;
    s.queued_bytes = 0;
    for (const auto& [id, c] : clients_) {
      if (c->fd) s.queued_bytes += c->queued_bytes();
    }
    return s;
  }

  std::size_t max_queued_bytes_per_client() const {
    return config_.max_queued_text_bytes + config_.max_queued_binary_bytes +
           std::max(config_.max_queued_text_bytes, config_.max_queued_binary_bytes) + kControlSlack;
  }

 private:
  enum class Phase { kCreated, kRunning, kStopping, kStopped };

  struct Delivery {
    std::uint64_t client;
    std::string label;
    std::string text;
  };

  void run() {
    try {
      loop();
    } catch (const std::exception& e) {
      const std::lock_guard lock(mutex_);
      log(std::string("websocket: hub thread failed, closing every client: ") + e.what());
    }
    const std::lock_guard lock(mutex_);
    for (auto& [id, c] : clients_) close_now(*c);
    clients_.clear();
    closed_.clear();
    dirty_.clear();
    phase_ = Phase::kStopped;
  }

  void loop() {
    std::vector<epoll_event> events(64);
    std::vector<Delivery> deliveries;
    bool shutting_down = false;
    Clock::time_point shutdown_deadline;
    while (true) {
      int timeout = 0;
      {
        const std::lock_guard lock(mutex_);
        const auto wait = std::chrono::ceil<std::chrono::milliseconds>(next_sweep_ - Clock::now());
        timeout = static_cast<int>(
            std::clamp<std::chrono::milliseconds::rep>(wait.count(), 0, kMaxSweepInterval.count()));
      }
      const int n =
          ::epoll_wait(epoll_.get(), events.data(), static_cast<int>(events.size()), timeout);
      if (n < 0 && errno != EINTR) throw std::runtime_error("epoll_wait: " + errno_text(errno));

      {
        const std::lock_guard lock(mutex_);
        const Clock::time_point now = Clock::now();
        for (int i = 0; i < n; ++i) {
          const std::uint64_t id = events[i].data.u64;
          if (id == kWakeId) {
            std::uint64_t count = 0;
            [[maybe_unused]] const ssize_t r = ::read(wake_.get(), &count, sizeof(count));
          } else if (const auto it = clients_.find(id); it != clients_.end()) {
            on_event(*it->second, events[i].events, now);
          }
        }
        process_dirty(now);
        if (phase_ == Phase::kStopping && !shutting_down) {
          shutting_down = true;
          shutdown_deadline = now + config_.close_timeout;
          for (auto& [id, c] : clients_) {
            if (!c->fd) continue;
            begin_close(
                *c, encode_websocket_close(websocket_close::kGoingAway, "server is shutting down"),
                now);
            flush(*c, now);
          }
          schedule(shutdown_deadline);
        }
        if (now >= next_sweep_) expire(now);
        for (const std::uint64_t id : closed_) clients_.erase(id);
        closed_.clear();
        if (shutting_down && (clients_.empty() || now >= shutdown_deadline)) return;
        deliveries.swap(pending_messages_);
      }

      for (Delivery& d : deliveries) deliver(d);
      deliveries.clear();
    }
  }

  void deliver(Delivery& d) {
    try {
      config_.on_message(d.client, d.label, std::move(d.text));
    } catch (const std::exception& e) {
      const std::lock_guard lock(mutex_);
      log("websocket: on_message failed for " + d.label + ": " + e.what());
    } catch (...) {
      const std::lock_guard lock(mutex_);
      log("websocket: on_message failed for " + d.label + " with an unknown exception");
    }
  }

  void process_dirty(Clock::time_point now) {
    for (const std::uint64_t id : dirty_) {
      const auto it = clients_.find(id);
      if (it == clients_.end()) continue;
      WebSocketConnection& c = *it->second;
      c.dirty = false;
      if (!c.fd) continue;
      if (!c.early_input.empty()) consume(c, std::exchange(c.early_input, std::string()), now);
      if (c.fd) flush(c, now);
    }
    dirty_.clear();
  }

  void on_event(WebSocketConnection& c, std::uint32_t events, Clock::time_point now) {
    if (!c.fd) return;
    // EPOLLHUP: both directions are shut (reset, or both sides sent FIN); nothing can be
    // delivered any more, and under level triggering it would otherwise fire forever.
    if (events & (EPOLLERR | EPOLLHUP)) {
      close_now(c);
      return;
    }
    if ((events & EPOLLOUT) && !flush(c, now)) return;
    if (events & (EPOLLIN | EPOLLRDHUP)) read_input(c, now);
    if (c.fd) flush(c, now);  // pongs and close replies produced by the input
  }

  void read_input(WebSocketConnection& c, Clock::time_point now) {
    for (int i = 0; i < kReadsPerEvent && c.fd; ++i) {
      const ssize_t n = ::recv(c.fd.get(), read_buffer_.data(), read_buffer_.size(), 0);
      if (n > 0) {
        if (c.close_sent) {
          c.discarded_bytes += static_cast<std::size_t>(n);
          if (c.discarded_bytes > kMaxDiscardBytes) {
            close_now(c);
            return;
          }
        }
        consume(c, std::string_view(read_buffer_.data(), static_cast<std::size_t>(n)), now);
        if (static_cast<std::size_t>(n) < read_buffer_.size()) return;
      } else if (n == 0) {
        close_now(c);  // the client is gone, after its close frame or without one
        return;
      } else if (errno == EINTR) {
        continue;
      } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
        return;
      } else {
        close_now(c);
        return;
      }
    }
  }

  void consume(WebSocketConnection& c, std::string_view bytes, Clock::time_point now) {
    // After the client's close frame or a protocol error nothing it sends has a meaning.
    while (c.fd && !c.close_received && c.parser.state() != WebSocketFrameParser::State::kError) {
      bytes.remove_prefix(c.parser.feed(bytes));
      switch (c.parser.state()) {
        case WebSocketFrameParser::State::kComplete:
          handle(c, c.parser.take(), now);
          break;
        case WebSocketFrameParser::State::kError:
          log("websocket: closing " + c.label + " with " + std::to_string(c.parser.error_code()) +
              ": " + c.parser.error_message());
          fail(c, c.parser.error_code(), c.parser.error_message(), now);
          return;
        case WebSocketFrameParser::State::kIncomplete:
          return;  // all of bytes consumed
      }
    }
  }

  void handle(WebSocketConnection& c, WebSocketMessage message, Clock::time_point now) {
    switch (message.opcode) {
      case WebSocketOpcode::kText:
        if (!c.close_queued && config_.on_message) {
          pending_messages_.push_back({c.id, c.label, std::move(message.payload)});
        }
        break;
      case WebSocketOpcode::kBinary:
        fail(c, websocket_close::kUnsupportedData, "this endpoint accepts only text messages", now);
        break;
      case WebSocketOpcode::kPing:
        if (!c.close_queued) queue_pong(c, message.payload);
        break;
      case WebSocketOpcode::kPong:
        // Any pong proves the client alive; RFC 6455 §5.5.3 allows unsolicited ones.
        c.awaiting_pong = false;
        c.next_ping = now + config_.ping_interval;
        schedule(c.next_ping);
        break;
      case WebSocketOpcode::kClose:
        c.close_received = true;
        if (!c.close_queued) {
          // Echo the client's code (RFC 6455 §5.5.1); a close without one is answered likewise.
          begin_close(c,
                      message.close_code == websocket_close::kNoStatus
                          ? encode_websocket_frame(WebSocketOpcode::kClose, {})
                          : encode_websocket_close(message.close_code, {}),
                      now);
        }
        if (c.close_sent) close_now(c);  // both close frames exchanged: the server closes TCP
        break;
      case WebSocketOpcode::kContinuation:
        break;  // the parser never produces it
    }
  }

  // Fails the connection (RFC 6455 §7.1.7): our close frame, then our sending side shuts down
  // without waiting for a reply. Input is still drained until the client closes too, because
  // closing a socket with unread input makes the kernel send RST, which can destroy the close
  // frame before the client reads it.
  void fail(WebSocketConnection& c, std::uint16_t code, std::string_view reason,
            Clock::time_point now) {
    begin_close(c, encode_websocket_close(code, reason), now);
    c.failing = true;
  }

  void queue_pong(WebSocketConnection& c, std::string_view payload) {
    // Only the latest ping needs an answer (RFC 6455 §5.5.3), so a client flooding pings while not
    // reading cannot grow the control queue.
    for (auto it = c.control.begin(); it != c.control.end();) {
      if (it->kind == Kind::kPong) {
        c.queued_control -= it->bytes->size();
        it = c.control.erase(it);
      } else {
        ++it;
      }
    }
    queue_control(c, Kind::kPong, encode_websocket_frame(WebSocketOpcode::kPong, payload));
  }

  void queue_control(WebSocketConnection& c, Kind kind, std::string frame) {
    c.queued_control += frame.size();
    c.control.push_back({std::make_shared<const std::string>(std::move(frame)), kind, 0});
    stats_.peak_client_queued_bytes = std::max(stats_.peak_client_queued_bytes, c.queued_bytes());
  }

  // Queues our close frame in place of everything not yet started: after it nothing may be sent
  // (RFC 6455 §5.5.1), and what was queued is stale anyway.
  void begin_close(WebSocketConnection& c, std::string frame, Clock::time_point now) {
    if (c.close_queued) return;
    c.data.clear();
    c.queued_text = 0;
    c.queued_binary = 0;
    c.control.clear();
    c.queued_control = 0;
    c.dropped = 0;
    queue_control(c, Kind::kClose, std::move(frame));
    c.close_queued = true;
    c.close_deadline = now + config_.close_timeout;
    schedule(c.close_deadline);
  }

  void enqueue(WebSocketConnection& c, const OutgoingFrame& frame, Clock::time_point now) {
    if (c.close_queued) return;
    const bool had_output = c.has_output();
    const std::size_t size = frame.bytes->size();
    if (frame.kind == Kind::kText) {
      if (c.queued_text + size > config_.max_queued_text_bytes) {
        ++stats_.clients_closed_slow;
        log("websocket: " + c.label + " is not reading its events (" +
            std::to_string(c.queued_text) + " bytes unsent, max_queued_text_bytes " +
            std::to_string(config_.max_queued_text_bytes) + "); closing it with 1013");
        begin_close(c,
                    encode_websocket_close(websocket_close::kTryAgainLater,
                                           "too slow to receive events; reconnect and resync"),
                    now);
        mark_dirty(c);
        return;
      }
      c.queued_text += size;
      c.data.push_back(frame);
    } else {
      // The oldest chunks go first: the client refetches everything since the last chunk it has.
      while (c.queued_binary + size > config_.max_queued_binary_bytes) {
        const auto oldest = std::find_if(c.data.begin(), c.data.end(), [](const OutgoingFrame& f) {
          return f.kind == Kind::kBinary;
        });
        if (oldest == c.data.end()) break;
        record_drop(c, oldest->chunk_id);
        c.queued_binary -= oldest->bytes->size();
        c.data.erase(oldest);
      }
      if (c.queued_binary + size > config_.max_queued_binary_bytes) {
        record_drop(c, frame.chunk_id);
        return;
      }
      c.queued_binary += size;
      c.data.push_back(frame);
    }
    stats_.peak_client_queued_bytes = std::max(stats_.peak_client_queued_bytes, c.queued_bytes());
    // With output already pending, EPOLLOUT is armed and the hub thread will get to it.
    if (!had_output) mark_dirty(c);
  }

  void record_drop(WebSocketConnection& c, std::uint32_t chunk_id) {
    if (c.dropped == 0) c.first_dropped_id = chunk_id;
    c.last_dropped_id = chunk_id;
    ++c.dropped;
    ++stats_.binary_frames_dropped;
  }

  // Writes until the socket is full or nothing is left. False when the client was closed.
  bool flush(WebSocketConnection& c, Clock::time_point now) {
    while (c.fd) {
      if (!c.sending && !next_frame(c)) break;
      const std::string& bytes = *c.sending->bytes;
      const ssize_t n = ::send(c.fd.get(), bytes.data() + c.sending_offset,
                               bytes.size() - c.sending_offset, MSG_NOSIGNAL);
      if (n > 0) {
        c.sending_offset += static_cast<std::size_t>(n);
        if (c.sending_offset < bytes.size()) continue;
        const Kind kind = c.sending->kind;
        c.sending.reset();
        if (kind == Kind::kPing) {
          c.ping_sent = now;  // the pong timeout counts from when the ping could leave
        } else if (kind == Kind::kClose) {
          c.close_sent = true;
          if (c.close_received) {
            close_now(c);  // both close frames exchanged: the server closes TCP first
          } else if (c.failing) {
            ::shutdown(c.fd.get(), SHUT_WR);
          }
        }
      } else if (n < 0 && errno == EINTR) {
        continue;
      } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        break;
      } else {
        close_now(c);  // EPIPE or ECONNRESET: the client is gone
      }
    }
    if (!c.fd) return false;
    update_interest(c);
    return true;
  }

  // Moves the next frame to write into c.sending: control frames first. False when none.
  bool next_frame(WebSocketConnection& c) {
    if (c.close_sent) return false;
    if (c.data.empty() && c.control.empty() && c.dropped > 0 && !c.close_queued) {
      // Caught up after losing chunks: say so, so the client knows to refetch.
      const nlohmann::json notice = {{"type", "binary_dropped"},
                                     {"count", c.dropped},
                                     {"first_id", c.first_dropped_id},
                                     {"last_id", c.last_dropped_id}};
      const std::string frame = encode_websocket_frame(WebSocketOpcode::kText, notice.dump());
      c.dropped = 0;
      c.queued_text += frame.size();
      c.data.push_back({std::make_shared<const std::string>(frame), Kind::kText, 0});
    }
    std::deque<OutgoingFrame>& queue = c.control.empty() ? c.data : c.control;
    if (queue.empty()) return false;
    OutgoingFrame frame = std::move(queue.front());
    queue.pop_front();
    const std::size_t size = frame.bytes->size();
    switch (frame.kind) {
      case Kind::kText:
        c.queued_text -= size;
        break;
      case Kind::kBinary:
        c.queued_binary -= size;
        break;
      default:
        c.queued_control -= size;
        break;
    }
    c.sending = std::move(frame);
    c.sending_offset = 0;
    return true;
  }

  void expire(Clock::time_point now) {
    Clock::time_point next = now + kMaxSweepInterval;
    for (auto& [id, cp] : clients_) {
      WebSocketConnection& c = *cp;
      if (!c.fd) continue;
      if (c.close_queued) {
        if (now >= c.close_deadline) {
          close_now(c);  // the client neither read our close frame nor answered it in time
          continue;
        }
        next = std::min(next, c.close_deadline);
      } else if (c.awaiting_pong) {
        const Clock::time_point limit = c.ping_sent + config_.pong_timeout;
        if (now >= limit) {
          ++stats_.clients_closed_unresponsive;
          log("websocket: " + c.label + " did not answer a ping within " +
              std::to_string(config_.pong_timeout.count()) + " ms; disconnecting it");
          close_now(c);
          continue;
        }
        next = std::min(next, limit);
      } else if (now >= c.next_ping) {
        queue_control(c, Kind::kPing, encode_websocket_frame(WebSocketOpcode::kPing, {}));
        c.awaiting_pong = true;
        c.ping_sent = now;
        if (!flush(c, now)) continue;
        next = std::min(next, now + config_.pong_timeout);
      } else {
        next = std::min(next, c.next_ping);
      }
    }
    next_sweep_ = next;
  }

  void update_interest(WebSocketConnection& c) {
    const std::uint32_t events =
        EPOLLIN | EPOLLRDHUP | (c.has_output() ? std::uint32_t{EPOLLOUT} : 0u);
    if (events == c.events) return;
    epoll_event ev{};
    ev.events = events;
    ev.data.u64 = c.id;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, c.fd.get(), &ev) != 0) {
      log("websocket: epoll_ctl failed for " + c.label + ": " + errno_text(errno));
      close_now(c);
      return;
    }
    c.events = events;
  }

  // Closes the socket now; the entry is erased at the end of the hub thread's batch.
  void close_now(WebSocketConnection& c) {
    if (!c.fd) return;
    ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, c.fd.get(), nullptr);
    c.fd.reset();
    c.data.clear();
    c.control.clear();
    c.sending.reset();
    c.queued_text = c.queued_binary = c.queued_control = 0;
    --live_clients_;
    closed_.push_back(c.id);
  }

  void mark_dirty(WebSocketConnection& c) {
    if (c.dirty) return;
    c.dirty = true;
    const bool first = dirty_.empty();
    dirty_.push_back(c.id);
    if (first) wake();
  }

  void schedule(Clock::time_point when) { next_sweep_ = std::min(next_sweep_, when); }

  void wake() {
    const std::uint64_t one = 1;
    // Failure means the counter is saturated, i.e. a wake-up is already pending.
    [[maybe_unused]] const ssize_t written = ::write(wake_.get(), &one, sizeof(one));
  }

  void log(std::string_view message) const {
    if (config_.log) {
      config_.log(message);
    } else {
      std::cerr << message << std::endl;
    }
  }

  const HubConfig config_;
  UniqueFd wake_;  // eventfd: other threads write it to interrupt epoll_wait
  UniqueFd epoll_;
  std::vector<char> read_buffer_;  // used by the hub thread only
  std::thread thread_;
  std::mutex join_mutex_;  // two threads calling stop() must not both join

  mutable std::mutex mutex_;
  std::thread::id thread_id_;  // of the hub thread; join() clears thread_'s own copy
  Phase phase_ = Phase::kCreated;
  std::unordered_map<std::uint64_t, std::unique_ptr<WebSocketConnection>> clients_;
  std::size_t live_clients_ = 0;
  std::vector<std::uint64_t> closed_;  // erased after each batch of events
  std::vector<std::uint64_t> dirty_;   // clients with work queued by other threads
  std::vector<Delivery> pending_messages_;
  std::uint64_t next_id_ = kWakeId + 1;
  Clock::time_point next_sweep_ = Clock::now() + kMaxSweepInterval;
  HubStats stats_;
};

WebSocketHub::WebSocketHub(HubConfig config) : impl_(std::make_shared<Impl>(std::move(config))) {}

WebSocketHub::~WebSocketHub() {
  try {
    impl_->stop();
  } catch (const std::exception& e) {
    // Only possible when the hub is destroyed from its own on_message: nothing better to do than
    // to say so, since a destructor cannot throw.
    std::cerr << "websocket: " << e.what() << std::endl;
  }
}

void WebSocketHub::start() {
  impl_->start();
}

void WebSocketHub::stop() {
  impl_->stop();
}

UpgradeHandler WebSocketHub::adopt(std::string client_label) {
  std::weak_ptr<Impl> weak = impl_;
  return [weak, label = std::move(client_label)](int fd, std::string buffered) {
    if (const std::shared_ptr<Impl> impl = weak.lock()) {
      impl->adopt(fd, label, std::move(buffered));
    } else {
      refuse(UniqueFd(fd), websocket_close::kGoingAway, "the event hub is gone");
    }
  };
}

void WebSocketHub::broadcast_text(std::string json) {
  if (!is_valid_utf8(json)) {
    throw std::invalid_argument(
        "WebSocket text must be valid UTF-8; browsers drop the connection over it");
  }
  if (json.size() + kMaxFrameHeaderBytes > impl_->config().max_queued_text_bytes) {
    throw std::length_error("WebSocket event of " + std::to_string(json.size()) +
                            " bytes exceeds max_queued_text_bytes (" +
                            std::to_string(impl_->config().max_queued_text_bytes) +
                            "); send bulk data as binary chunks or raise the limit");
  }
  impl_->broadcast(
      {std::make_shared<const std::string>(encode_websocket_frame(WebSocketOpcode::kText, json)),
       Kind::kText, 0});
}

bool WebSocketHub::send_text(std::uint64_t client, std::string json) {
  if (!is_valid_utf8(json)) {
    throw std::invalid_argument(
        "WebSocket text must be valid UTF-8; browsers drop the connection over it");
  }
  if (json.size() + kMaxFrameHeaderBytes > impl_->config().max_queued_text_bytes) {
    throw std::length_error("WebSocket message of " + std::to_string(json.size()) +
                            " bytes exceeds max_queued_text_bytes (" +
                            std::to_string(impl_->config().max_queued_text_bytes) + ")");
  }
  return impl_->send_to(
      client,
      {std::make_shared<const std::string>(encode_websocket_frame(WebSocketOpcode::kText, json)),
       Kind::kText, 0});
}

void WebSocketHub::broadcast_binary(std::uint8_t op, std::uint32_t id, std::string payload) {
  const std::size_t payload_bytes = kBinaryPrefixBytes + payload.size();
  if (payload_bytes + kMaxFrameHeaderBytes > impl_->config().max_queued_binary_bytes) {
    throw std::length_error("WebSocket binary chunk of " + std::to_string(payload.size()) +
                            " bytes exceeds max_queued_binary_bytes (" +
                            std::to_string(impl_->config().max_queued_binary_bytes) +
                            "); split it or raise the limit");
  }
  const auto ns =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  std::string frame;
  frame.reserve(kMaxFrameHeaderBytes + payload_bytes);
  append_websocket_frame_header(frame, WebSocketOpcode::kBinary, payload_bytes);
  frame.push_back(static_cast<char>(op));
  append_le(frame, id, 4);
  append_le(frame, ns, 8);
  frame.append(payload);
  impl_->broadcast({std::make_shared<const std::string>(std::move(frame)), Kind::kBinary, id});
}

std::size_t WebSocketHub::clients() const {
  return impl_->clients();
}

HubStats WebSocketHub::stats() const {
  return impl_->stats();
}

std::size_t WebSocketHub::max_queued_bytes_per_client() const {
  return impl_->max_queued_bytes_per_client();
}

}  // namespace scanplan::http
