#include "http/http_server.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "http/ascii.hpp"
#include "http/connection.hpp"
#include "http/http_error.hpp"
#include "http/status.hpp"

namespace scanplan::http {
namespace {

static_assert(std::atomic<bool>::is_always_lock_free,
              "stop() relies on a lock-free atomic to be async-signal-safe");

// epoll user data for the two non-connection descriptors; connection ids start above them.
constexpr std::uint64_t kListenerId = 0;
constexpr std::uint64_t kWakeId = 1;
constexpr std::uint64_t kFirstConnectionId = 2;

constexpr std::size_t kReadBufferBytes = 64 * 1024;
// Reads per readiness event, so one fast uploader cannot starve the other connections.
constexpr int kReadsPerEvent = 4;
// Connections beyond max_connections still get their 503 while this many are being rejected;
// past that they are closed unanswered, since answering costs a descriptor each.
constexpr std::size_t kRejectBacklog = 64;
// After our final response we shut down writing and drain the client's leftovers for a while:
// closing with unread input makes the kernel send RST, which can destroy the response in flight.
// The bytes drained are capped at a large scan upload (a 350k-point PLY is 9 MB): a scan refused
// at its headers (no operator token) is still on its way, and cutting it off at 1 MiB reset the
// connection before the client had read its 403. The time bounds the work either way.
constexpr std::chrono::milliseconds kLingerTime{2000};
constexpr std::size_t kMaxLingerBytes = 64u << 20;
// Out of descriptors, the listener stays readable; pausing it avoids a busy loop.
constexpr std::chrono::milliseconds kAcceptPause{100};
// Upper bound on how long epoll_wait sleeps, so deadlines are checked regularly.
constexpr std::chrono::milliseconds kMaxSweepInterval{1000};
constexpr std::string_view kContinue = "HTTP/1.1 100 Continue\r\n\r\n";

std::string errno_text(int err) {
  return std::generic_category().message(err);
}

std::string endpoint_text(const std::string& host, std::uint16_t port) {
  const bool ipv6 = host.find(':') != std::string::npos;
  return (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

std::string peer_text(const sockaddr_storage& addr) {
  char text[INET6_ADDRSTRLEN] = {};
  if (addr.ss_family == AF_INET) {
    const auto& in = reinterpret_cast<const sockaddr_in&>(addr);
    inet_ntop(AF_INET, &in.sin_addr, text, sizeof(text));
    return std::string(text) + ":" + std::to_string(ntohs(in.sin_port));
  }
  if (addr.ss_family == AF_INET6) {
    const auto& in6 = reinterpret_cast<const sockaddr_in6&>(addr);
    inet_ntop(AF_INET6, &in6.sin6_addr, text, sizeof(text));
    // Appended, not "[" + ...: GCC 12 warns of a false overlap in the operator+ chain.
    std::string out = "[";
    out += text;
    out += "]:";
    out += std::to_string(ntohs(in6.sin6_port));
    return out;
  }
  return "unknown";
}

// The client's address without its port: what max_connections_per_address counts.
std::string address_text(const std::string& peer) {
  const std::size_t colon = peer.rfind(':');
  return colon == std::string::npos ? peer : peer.substr(0, colon);
}

// Linux reports network errors already pending on a new connection through accept(2); they
// concern that one client, and the listener is fine (accept(2), "Error handling").
bool concerns_one_client(int err) {
  switch (err) {
    case ECONNABORTED:
    case EPROTO:
    case ENETDOWN:
    case ENOPROTOOPT:
    case EHOSTDOWN:
    case ENONET:
    case EHOSTUNREACH:
    case EOPNOTSUPP:
    case ENETUNREACH:
      return true;
    default:
      return false;
  }
}

bool has_close_token(const Response& response) {
  bool close = false;
  for (const Header& h : response.headers) {
    if (!ascii::iequals(h.name, "connection")) continue;
    ascii::for_each_list_element(
        h.value, [&](std::string_view token) { close = close || ascii::iequals(token, "close"); });
  }
  return close;
}

}  // namespace

HttpServer::HttpServer(ServerConfig config, Handler handler)
    : config_(std::move(config)),
      handler_(std::move(handler)),
      next_id_(kFirstConnectionId),
      read_buffer_(kReadBufferBytes) {
  if (!handler_) throw std::invalid_argument("HttpServer needs a request handler");
  wake_.reset(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!wake_) throw std::runtime_error("cannot create eventfd: " + errno_text(errno));
}

HttpServer::~HttpServer() = default;

void HttpServer::start() {
  if (listener_) throw std::logic_error("HttpServer::start() called twice");
  const std::string where = "cannot listen on " + endpoint_text(config_.host, config_.port);

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port_text = std::to_string(config_.port);
  const int rc = ::getaddrinfo(config_.host.empty() ? nullptr : config_.host.c_str(),
                               port_text.c_str(), &hints, &found);
  if (rc != 0) throw std::runtime_error(where + ": cannot resolve host: " + gai_strerror(rc));
  const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> addresses(found, &::freeaddrinfo);

  int last_error = EADDRNOTAVAIL;
  UniqueFd listener;
  for (const addrinfo* ai = addresses.get(); ai != nullptr; ai = ai->ai_next) {
    UniqueFd fd(
        ::socket(ai->ai_family, ai->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, ai->ai_protocol));
    if (!fd) {
      last_error = errno;
      continue;
    }
    // Lets a restarted server rebind while old connections sit in TIME_WAIT.
    const int one = 1;
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    if (config_.reuse_port &&
        ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEPORT, &one, sizeof(one)) != 0) {
      last_error = errno;
      continue;
    }
    if (::bind(fd.get(), ai->ai_addr, ai->ai_addrlen) != 0 || ::listen(fd.get(), SOMAXCONN) != 0) {
      last_error = errno;
      continue;
    }
    listener = std::move(fd);
    break;
  }
  if (!listener) throw std::runtime_error(where + ": " + errno_text(last_error));

  sockaddr_storage bound{};
  socklen_t bound_len = sizeof(bound);
  if (::getsockname(listener.get(), reinterpret_cast<sockaddr*>(&bound), &bound_len) != 0) {
    throw std::runtime_error(where + ": getsockname failed: " + errno_text(errno));
  }
  const std::uint16_t port = bound.ss_family == AF_INET6
                                 ? ntohs(reinterpret_cast<const sockaddr_in6&>(bound).sin6_port)
                                 : ntohs(reinterpret_cast<const sockaddr_in&>(bound).sin_port);

  UniqueFd epoll(::epoll_create1(EPOLL_CLOEXEC));
  if (!epoll) throw std::runtime_error(where + ": epoll_create1 failed: " + errno_text(errno));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u64 = kListenerId;
  if (::epoll_ctl(epoll.get(), EPOLL_CTL_ADD, listener.get(), &ev) != 0) {
    throw std::runtime_error(where + ": epoll_ctl failed: " + errno_text(errno));
  }
  ev.data.u64 = kWakeId;
  if (::epoll_ctl(epoll.get(), EPOLL_CTL_ADD, wake_.get(), &ev) != 0) {
    throw std::runtime_error(where + ": epoll_ctl failed: " + errno_text(errno));
  }

  listener_ = std::move(listener);
  epoll_ = std::move(epoll);
  port_ = port;
}

void HttpServer::stop() {
  stop_requested_.store(true);
  const std::uint64_t one = 1;
  // Failure means the counter is saturated, i.e. a wake-up is already pending.
  [[maybe_unused]] const ssize_t written = ::write(wake_.get(), &one, sizeof(one));
}

void HttpServer::post(std::function<void()> task) {
  {
    const std::lock_guard lock(posted_mutex_);
    posted_.push_back(std::move(task));
  }
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(wake_.get(), &one, sizeof(one));
}

void HttpServer::run() {
  if (!listener_) throw std::logic_error("HttpServer::run() called before start()");
  std::vector<epoll_event> events(64);
  next_sweep_ = Clock::now() + kMaxSweepInterval;

  while (!stop_requested_.load()) {
    Clock::time_point now = Clock::now();
    Clock::time_point wake_at = next_sweep_;
    if (listener_paused_) wake_at = std::min(wake_at, listener_resume_);
    const auto wait = std::chrono::ceil<std::chrono::milliseconds>(wake_at - now);
    const int timeout = static_cast<int>(
        std::clamp<std::chrono::milliseconds::rep>(wait.count(), 0, kMaxSweepInterval.count()));

    const int n =
        ::epoll_wait(epoll_.get(), events.data(), static_cast<int>(events.size()), timeout);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("HTTP server event loop failed: epoll_wait: " + errno_text(errno));
    }
    now = Clock::now();
    for (int i = 0; i < n; ++i) {
      const std::uint64_t id = events[i].data.u64;
      if (id == kListenerId) {
        accept_all(now);
      } else if (id == kWakeId) {
        on_wake();
      } else if (const auto it = connections_.find(id); it != connections_.end()) {
        on_event(*it->second, events[i].events, now);
      }
    }
    if (listener_paused_ && now >= listener_resume_) {
      epoll_event ev{};
      ev.events = EPOLLIN;
      ev.data.u64 = kListenerId;
      if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, listener_.get(), &ev) == 0) {
        listener_paused_ = false;
      } else {
        listener_resume_ = now + kAcceptPause;
      }
    }
    if (now >= next_sweep_) expire(now);
    for (const std::uint64_t id : closed_) connections_.erase(id);
    closed_.clear();
  }

  connections_.clear();
  closed_.clear();
  listener_.reset();
}

void HttpServer::on_wake() {
  std::uint64_t count = 0;
  [[maybe_unused]] const ssize_t r = ::read(wake_.get(), &count, sizeof(count));
  std::vector<std::function<void()>> tasks;
  {
    const std::lock_guard lock(posted_mutex_);
    tasks.swap(posted_);
  }
  for (auto& task : tasks) {
    try {
      task();
    } catch (const std::exception& e) {
      log(std::string("http: posted task failed: ") + e.what());
    } catch (...) {
      log("http: posted task failed with an unknown exception");
    }
  }
}

void HttpServer::accept_all(Clock::time_point now) {
  while (true) {
    sockaddr_storage addr{};
    socklen_t addr_len = sizeof(addr);
    const int fd = ::accept4(listener_.get(), reinterpret_cast<sockaddr*>(&addr), &addr_len,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      if (err == EAGAIN || err == EWOULDBLOCK) return;
      if (err == EINTR || concerns_one_client(err)) continue;
      log("http: accept failed: " + errno_text(err) + "; pausing new connections for " +
          std::to_string(kAcceptPause.count()) + " ms");
      pause_listener(now);
      return;
    }
    UniqueFd client(fd);
    const std::size_t limit = config_.limits.max_connections;
    const bool over_limit = connections_.size() >= limit;
    if (over_limit && connections_.size() >= limit + kRejectBacklog) continue;

    // Responses go out in one send each; Nagle would hold back the tail of a response until the
    // client's delayed ACK, adding ~40 ms to every keep-alive request.
    const int one = 1;
    ::setsockopt(client.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));

    const std::uint64_t id = next_id_++;
    std::string peer = peer_text(addr);
    std::string address = address_text(peer);
    const std::size_t from_there = static_cast<std::size_t>(
        std::count_if(connections_.begin(), connections_.end(),
                      [&](const auto& c) { return c.second->fd && c.second->address == address; }));
    const bool over_address_limit = from_there >= config_.limits.max_connections_per_address;
    auto conn = std::make_unique<Connection>(id, std::move(client), std::move(peer),
                                             std::move(address), config_.limits, now);
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLRDHUP;
    ev.data.u64 = id;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, conn->fd.get(), &ev) != 0) {
      log("http: cannot watch a new connection: " + errno_text(errno));
      continue;
    }
    conn->events = ev.events;
    Connection& c = *connections_.emplace(id, std::move(conn)).first->second;
    if (over_limit) {
      queue_error(
          c, 503,
          "the server already has " + std::to_string(limit) + " connections open; retry later");
    } else if (over_address_limit) {
      queue_error(c, 503,
                  "this address already holds " +
                      std::to_string(config_.limits.max_connections_per_address) +
                      " connections; close some or retry later");
    }
    settle(c, now);
  }
}

void HttpServer::pause_listener(Clock::time_point now) {
  if (listener_paused_) return;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, listener_.get(), nullptr);
  listener_paused_ = true;
  listener_resume_ = now + kAcceptPause;
}

void HttpServer::on_event(Connection& conn, std::uint32_t events, Clock::time_point now) {
  if (!conn.fd) return;
  // EPOLLHUP means both directions are shut (reset, or both sides sent FIN): nothing written can
  // arrive any more, and under level triggering it would otherwise fire forever.
  if (events & (EPOLLERR | EPOLLHUP)) {
    close(conn);
    return;
  }
  if (conn.lingering) {
    discard_input(conn);
    return;
  }
  if ((events & EPOLLOUT) && !flush(conn, now)) return;
  if (events & (EPOLLIN | EPOLLRDHUP)) read_input(conn, now);
  settle(conn, now);
}

bool HttpServer::can_read(const Connection& conn) const {
  return !conn.closing && !conn.peer_eof && !conn.upgrade &&
         conn.queued_responses < config_.limits.max_pipelined &&
         conn.out.pending_bytes() < config_.limits.max_queued_bytes;
}

void HttpServer::read_input(Connection& conn, Clock::time_point now) {
  for (int i = 0; i < kReadsPerEvent && conn.fd && can_read(conn); ++i) {
    const ssize_t n = ::recv(conn.fd.get(), read_buffer_.data(), read_buffer_.size(), 0);
    if (n > 0) {
      if (conn.in_parsed == conn.in.size()) {
        conn.in.clear();
        conn.in_parsed = 0;
      }
      conn.in.append(read_buffer_.data(), static_cast<std::size_t>(n));
      conn.received += static_cast<std::uint64_t>(n);
      conn.last_activity = now;
      process(conn, now);
      if (static_cast<std::size_t>(n) < read_buffer_.size()) return;
    } else if (n == 0) {
      conn.peer_eof = true;
      return;
    } else if (errno == EINTR) {
      continue;
    } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
      return;
    } else {
      close(conn);
      return;
    }
  }
}

void HttpServer::discard_input(Connection& conn) {
  while (conn.fd) {
    const ssize_t n = ::recv(conn.fd.get(), read_buffer_.data(), read_buffer_.size(), 0);
    if (n > 0) {
      conn.lingered_bytes += static_cast<std::size_t>(n);
      if (conn.lingered_bytes > kMaxLingerBytes) close(conn);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      return;
    } else {
      close(conn);  // the client closed too (or reset): done
    }
  }
}

void HttpServer::process(Connection& conn, Clock::time_point now) {
  while (!conn.closing && !conn.upgrade && conn.queued_responses < config_.limits.max_pipelined &&
         conn.out.pending_bytes() < config_.limits.max_queued_bytes && !conn.unparsed().empty()) {
    conn.in_parsed += conn.parser.feed(conn.unparsed());
    const RequestParser::State state = conn.parser.state();
    if (state != RequestParser::State::kError &&
        (conn.parser.headers_complete() || state == RequestParser::State::kComplete) &&
        !admit(conn)) {
      break;
    }
    switch (state) {
      case RequestParser::State::kError:
        queue_error(conn, conn.parser.error_status(), conn.parser.error_message());
        break;
      case RequestParser::State::kComplete: {
        Request request = conn.parser.take();
        request.peer = conn.peer;
        respond(conn, std::move(request));
        break;
      }
      case RequestParser::State::kIncomplete:
        break;
    }
  }
  if (conn.closing) return;
  if (conn.parser.started() && !conn.head_timer) {
    conn.head_timer = true;
    conn.head_started = now;
  }
  if (conn.parser.headers_complete() && !conn.body_timer) {
    conn.body_timer = true;
    conn.body_started = now;
    conn.received_at_body = conn.received - conn.unparsed().size();
  }
  // Sent only once the headers passed every check, so a client told 413 never sends the body.
  if (conn.parser.expects_continue() && !conn.continue_sent) {
    conn.out.append(std::string(kContinue));
    conn.continue_sent = true;
  }
}

bool HttpServer::admit(Connection& conn) {
  if (conn.admitted) return true;
  conn.admitted = true;
  if (!config_.admit) return true;
  std::optional<Response> refusal;
  try {
    refusal = config_.admit(conn.parser.head());
  } catch (const std::exception& e) {
    log(std::string("http: admission check failed: ") + e.what());
    refusal = Response::error(500, "internal", "internal error while checking the request");
  }
  if (!refusal) return true;
  queue(conn, std::move(*refusal), /*keep_alive=*/false, conn.parser.head().method == "HEAD");
  ++conn.queued_responses;
  conn.closing = true;
  return false;
}

Response HttpServer::call_handler(const Request& request) {
  const auto internal_error = [&](std::string_view what) {
    log("http: " + request.method + " " + request.target + " failed: " + std::string(what));
    return Response::error(500, "internal",
                           "internal error while handling the request; see the server log");
  };
  try {
    return handler_(request);
  } catch (const HttpError& e) {
    if (e.status() < 400 || e.status() > 599) return internal_error(e.what());
    return Response::error(e.status(), e.code(), e.what());
  } catch (const std::exception& e) {
    return internal_error(e.what());
  } catch (...) {
    return internal_error("unknown exception");
  }
}

void HttpServer::respond(Connection& conn, Request request) {
  conn.head_timer = false;
  conn.body_timer = false;
  conn.admitted = false;
  conn.continue_sent = false;
  conn.served_any = true;

  Response response = call_handler(request);
  bool keep_alive = request.keep_alive() && !stop_requested_.load() && !has_close_token(response);
  if (response.status == 101 && response.on_upgrade) {
    conn.upgrade = std::move(response.on_upgrade);
    keep_alive = true;  // the socket lives on under the new protocol
  } else if (response.status < 200) {
    log("http: handler for " + request.method + " " + request.target + " returned status " +
        std::to_string(response.status) + (response.status == 101 ? " without on_upgrade" : ""));
    response = Response::error(500, "internal", "the handler produced an invalid response");
  }
  // HTTP/1.0 connections close by default, so staying open must be announced.
  if (keep_alive && request.version_minor == 0 && !response.header("Connection")) {
    response.set_header("Connection", "keep-alive");
  }
  queue(conn, std::move(response), keep_alive, request.method == "HEAD");
  ++conn.queued_responses;
  if (!keep_alive) conn.closing = true;
}

void HttpServer::queue(Connection& conn, Response response, bool keep_alive, bool head_request) {
  conn.out.append(serialize_head(response, keep_alive));
  if (!sends_body(response, head_request)) return;
  if (response.shared_owner) {
    conn.out.append_shared(response.shared_owner, response.shared_body);
  } else {
    conn.out.append(std::move(response.body));
  }
}

void HttpServer::queue_error(Connection& conn, int status, std::string_view message) {
  queue(conn, Response::error(status, error_code(status), message), false, false);
  ++conn.queued_responses;
  conn.closing = true;
}

bool HttpServer::flush(Connection& conn, Clock::time_point now) {
  while (conn.has_output()) {
    const ssize_t n = conn.out.send_some(conn.fd.get());
    if (n > 0) {
      conn.last_activity = now;
    } else if (n == 0) {
      break;  // the socket's buffer is full
    } else {
      close(conn);  // EPIPE or ECONNRESET: the client is gone
      return false;
    }
  }
  if (!conn.has_output()) conn.queued_responses = 0;
  return true;
}

void HttpServer::settle(Connection& conn, Clock::time_point now) {
  if (!conn.fd || conn.lingering) return;
  while (true) {
    process(conn, now);
    if (!flush(conn, now)) return;
    // Draining the output lifts pipelining backpressure; parse what was held back.
    if (conn.has_output() || conn.closing || conn.upgrade || conn.unparsed().empty()) break;
  }
  if (!conn.has_output()) {
    if (conn.upgrade) {
      hand_over(conn);
      return;
    }
    if (conn.peer_eof) {
      close(conn);  // everything the client sent has been answered
      return;
    }
    if (conn.closing) {
      start_linger(conn, now);
      return;
    }
  }

  const Limits& limits = config_.limits;
  if (conn.parser.started() && !conn.parser.headers_complete()) {
    conn.deadline = conn.head_started + limits.header_timeout;
  } else if (conn.parser.headers_complete() && conn.body_timer && !conn.has_output()) {
    // A stall, or a body that falls behind the minimum rate once the grace period is over.
    const double got = static_cast<double>(conn.received - conn.received_at_body);
    const auto behind =
        conn.body_started + limits.body_grace +
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
            got / static_cast<double>(std::max<std::size_t>(limits.min_body_bytes_per_s, 1))));
    conn.deadline = std::min(conn.last_activity + limits.body_timeout, behind);
  } else if (conn.parser.headers_complete() || conn.has_output()) {
    conn.deadline = conn.last_activity + limits.body_timeout;
  } else {
    conn.deadline =
        conn.last_activity + (conn.served_any ? limits.idle_timeout : limits.header_timeout);
  }
  next_sweep_ = std::min(next_sweep_, conn.deadline);
  update_interest(conn);
}

void HttpServer::start_linger(Connection& conn, Clock::time_point now) {
  ::shutdown(conn.fd.get(), SHUT_WR);
  conn.lingering = true;
  conn.deadline = now + kLingerTime;
  next_sweep_ = std::min(next_sweep_, conn.deadline);
  update_interest(conn);
  discard_input(conn);
}

void HttpServer::hand_over(Connection& conn) {
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, conn.fd.get(), nullptr);
  const int fd = conn.fd.release();
  std::string buffered(conn.unparsed());
  UpgradeHandler upgrade = std::move(conn.upgrade);
  closed_.push_back(conn.id);
  try {
    upgrade(fd, std::move(buffered));
  } catch (const std::exception& e) {
    log(std::string("http: upgrade handler failed: ") + e.what());
  } catch (...) {
    log("http: upgrade handler failed with an unknown exception");
  }
}

void HttpServer::on_timeout(Connection& conn, Clock::time_point now) {
  if (conn.lingering || conn.has_output()) {
    close(conn);  // the client stopped reading, or the linger period is over
    return;
  }
  if (!conn.parser.started()) {
    close(conn);  // idle keep-alive connection: closing silently is the convention
    return;
  }
  const std::string message =
      conn.parser.headers_complete()
          ? "request body stalled for more than " +
                std::to_string(config_.limits.body_timeout.count()) +
                " ms, or arrived slower than " +
                std::to_string(config_.limits.min_body_bytes_per_s) + " bytes/s"
          : "request header not received within " +
                std::to_string(config_.limits.header_timeout.count()) + " ms";
  queue_error(conn, 408, message);
  conn.last_activity = now;
  settle(conn, now);
}

void HttpServer::expire(Clock::time_point now) {
  Clock::time_point next = now + kMaxSweepInterval;
  for (auto& [id, conn] : connections_) {
    if (conn->fd && conn->deadline <= now) on_timeout(*conn, now);
    if (conn->fd) next = std::min(next, conn->deadline);
  }
  next_sweep_ = next;
}

void HttpServer::update_interest(Connection& conn) {
  std::uint32_t events = 0;
  if (conn.lingering || can_read(conn)) events |= EPOLLIN | EPOLLRDHUP;
  if (!conn.lingering && conn.has_output()) events |= EPOLLOUT;
  if (events == conn.events) return;
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = conn.id;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, conn.fd.get(), &ev) != 0) {
    log("http: epoll_ctl failed for " + conn.peer + ": " + errno_text(errno));
    close(conn);
    return;
  }
  conn.events = events;
}

void HttpServer::close(Connection& conn) {
  if (!conn.fd) return;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, conn.fd.get(), nullptr);
  conn.fd.reset();
  closed_.push_back(conn.id);
}

void HttpServer::log(std::string_view message) const {
  if (config_.log) {
    config_.log(message);
  } else {
    std::cerr << message << std::endl;
  }
}

}  // namespace scanplan::http
