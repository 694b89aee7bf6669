#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include "http/limits.hpp"
#include "http/output_queue.hpp"
#include "http/request_parser.hpp"
#include "http/response.hpp"
#include "http/unique_fd.hpp"

namespace scanplan::http {

// The state HttpServer keeps for one accepted socket. Plain data: the event loop owns the logic,
// so that every transition is visible in one place.
struct Connection {
  using Clock = std::chrono::steady_clock;

  Connection(std::uint64_t id_, UniqueFd fd_, std::string peer_, std::string address_,
             const Limits& limits, Clock::time_point now)
      : id(id_),
        fd(std::move(fd_)),
        peer(std::move(peer_)),
        address(std::move(address_)),
        parser(limits),
        last_activity(now),
        deadline(now) {}

  bool has_output() const { return !out.empty(); }
  std::string_view unparsed() const { return std::string_view(in).substr(in_parsed); }

  std::uint64_t id;
  UniqueFd fd;
  std::string peer;     // address and port, for messages
  std::string address;  // the client's address alone (max_connections_per_address)
  RequestParser parser;

  // Received bytes the parser has not consumed yet. Normally empty between reads; holds
  // pipelined requests while output backpressure pauses request processing.
  std::string in;
  std::size_t in_parsed = 0;

  OutputQueue out;                   // serialized responses not yet fully written
  std::size_t queued_responses = 0;  // responses appended since out was last drained
  std::uint64_t received = 0;        // bytes read from the socket, ever

  bool served_any = false;     // decides between header and idle timeout when nothing is pending
  bool continue_sent = false;  // "100 Continue" already sent for the current request
  bool head_timer = false;     // the header timeout is running for the current request
  Clock::time_point head_started;
  bool admitted = false;  // the current request's header section passed ServerConfig::admit
  // When the current request's header section was complete, and `received` then: the body's
  // rate is measured from there (Limits::min_body_bytes_per_s).
  bool body_timer = false;
  Clock::time_point body_started;
  std::uint64_t received_at_body = 0;

  bool closing = false;    // no further requests are processed; close once out is written
  bool peer_eof = false;   // the client shut down its sending side
  bool lingering = false;  // our side is shut down; discarding input until the client closes
  std::size_t lingered_bytes = 0;
  UpgradeHandler upgrade;  // hand the socket over once out is written

  Clock::time_point last_activity;  // last read or write progress
  Clock::time_point deadline;
  std::uint32_t events = 0;  // the epoll interest currently registered
};

}  // namespace scanplan::http
