#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "http/limits.hpp"
#include "http/request.hpp"
#include "http/response.hpp"
#include "http/unique_fd.hpp"

namespace scanplan::http {

struct Connection;

struct ServerConfig {
  std::string host = "127.0.0.1";  // numeric address or name; "::" or "0.0.0.0" for all
  std::uint16_t port = 8080;       // 0 picks an ephemeral port; see HttpServer::port()
  Limits limits;
  // Receives operational problems (handler exceptions, accept failures). Empty means stderr.
  std::function<void(std::string_view)> log;
  // Lets several servers, each with its own loop thread, listen on one port (SO_REUSEPORT): the
  // kernel spreads new connections over them, so the API uses more than one core. Start one
  // with the wanted port (0 for an ephemeral one), then the others on the port it got.
  bool reuse_port = false;
  // Called on the loop thread as soon as a request's header section is in, before its body is
  // read or "100 Continue" is sent: a response refuses the request (it is sent and the
  // connection closed, the body never read), so that a client without a valid token cannot
  // make the server receive and buffer hundreds of megabytes (issue 16). Empty: all admitted.
  std::function<std::optional<Response>(const Request& head)> admit;
};

// HTTP/1.1 server: one thread runs a level-triggered epoll loop over non-blocking sockets.
//
// Handlers run on the loop thread, one at a time, so they must be quick or hand work off; their
// responses are written in request order even when requests are pipelined. Transport problems are
// answered as JSON errors in the REST shape: parse errors with the parser's status (then close),
// stalled clients with 408, connections beyond the limit with 503. Writes use MSG_NOSIGNAL, so a
// client vanishing mid-response never raises SIGPIPE.
class HttpServer {
 public:
  using Handler = std::function<Response(const Request&)>;

  // Throws std::runtime_error if the wake-up eventfd cannot be created.
  HttpServer(ServerConfig config, Handler handler);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds and listens. Throws std::runtime_error naming the address and the reason, e.g.
  // "cannot listen on 127.0.0.1:8080: Address already in use".
  void start();

  // The bound port (the ephemeral one when configured with 0); valid after start().
  std::uint16_t port() const { return port_; }

  // Runs the event loop on the calling thread until stop(); then closes every connection and the
  // listening socket. A stopped server cannot be run again. Throws std::logic_error before start().
  void run();

  // Makes run() return soon. Thread-safe and async-signal-safe (an atomic store and a write to an
  // eventfd), so it may be called from a SIGINT handler. Calling it before run() makes run()
  // return at once.
  void stop();

  // Runs task on the loop thread at its next iteration: the way other threads touch state that
  // handlers own. Thread-safe, but not async-signal-safe (it takes a mutex). Exceptions thrown by
  // task are logged.
  void post(std::function<void()> task);

 private:
  using Clock = std::chrono::steady_clock;

  void accept_all(Clock::time_point now);
  void pause_listener(Clock::time_point now);
  void on_wake();
  void on_event(Connection& conn, std::uint32_t events, Clock::time_point now);
  void read_input(Connection& conn, Clock::time_point now);
  void discard_input(Connection& conn);
  void process(Connection& conn, Clock::time_point now);
  void respond(Connection& conn, Request request);
  // Queues `response` on the connection (its head, then its body: shared, or moved in).
  void queue(Connection& conn, Response response, bool keep_alive, bool head_request);
  // Whether the current request's head passes ServerConfig::admit; if not, queues the refusal.
  bool admit(Connection& conn);
  Response call_handler(const Request& request);
  void queue_error(Connection& conn, int status, std::string_view message);
  bool flush(Connection& conn, Clock::time_point now);
  void settle(Connection& conn, Clock::time_point now);
  void start_linger(Connection& conn, Clock::time_point now);
  void hand_over(Connection& conn);
  void on_timeout(Connection& conn, Clock::time_point now);
  void expire(Clock::time_point now);
  void update_interest(Connection& conn);
  void close(Connection& conn);
  bool can_read(const Connection& conn) const;
  void log(std::string_view message) const;

  ServerConfig config_;
  Handler handler_;
  UniqueFd wake_;  // eventfd: stop() and post() write it to interrupt epoll_wait
  UniqueFd epoll_;
  UniqueFd listener_;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_requested_{false};

  std::mutex posted_mutex_;
  std::vector<std::function<void()>> posted_;

  std::unordered_map<std::uint64_t, std::unique_ptr<Connection>> connections_;
  std::vector<std::uint64_t> closed_;  // erased after each batch of events
  std::uint64_t next_id_;
  std::vector<char> read_buffer_;
  Clock::time_point next_sweep_;
  bool listener_paused_ = false;
  Clock::time_point listener_resume_;
};

}  // namespace scanplan::http
