#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "http/limits.hpp"
#include "http/request.hpp"

namespace scanplan::http {

// Incremental HTTP/1.x request parser (RFC 9112).
//
// Bytes arrive in arbitrary pieces; feed() consumes only up to the end of the current request, so
// pipelined requests are never swallowed: after kComplete the caller take()s the request and feeds
// the unconsumed rest again. The parser is strict where leniency enables request smuggling or
// response splitting: lines must end in CRLF (a bare LF is rejected everywhere, consistently),
// obs-fold is rejected, Content-Length must be plain digits and agree across duplicates, and
// Content-Length together with Transfer-Encoding is rejected.
//
// Errors carry the status to answer with: 400 (malformed), 413 (body over the limit), 414 (target
// over the limit), 431 (header section over the limit), 501 (unsupported transfer coding),
// 505 (HTTP version other than 1.0/1.1). After an error the connection must be closed, because
// the position of the next request is unknown.
class RequestParser {
 public:
  enum class State { kIncomplete, kComplete, kError };

  explicit RequestParser(Limits limits = {});

  // Consumes a prefix of data and returns its length. Stops early at the end of a request
  // (state kComplete) or at an error (state kError); consumes nothing in those states.
  std::size_t feed(std::string_view data);

  State state() const { return state_; }

  // Moves out the complete request and readies the parser for the next one on the connection.
  // Throws std::logic_error unless state() is kComplete.
  Request take();

  int error_status() const { return error_status_; }
  const std::string& error_message() const { return error_message_; }

  // Forgets everything, including an error.
  void reset();

  // Whether bytes of the current request have arrived (blank lines between requests aside);
  // the connection is then in the header phase rather than idle.
  bool started() const { return started_; }
  // Whether the header section is complete and the body is being received.
  bool headers_complete() const { return headers_complete_; }
  // The request as parsed so far: once headers_complete(), its method, target, version and
  // header fields (the body still arriving).
  const Request& head() const { return request_; }
  // Whether the client waits for "100 Continue" before sending its body.
  bool expects_continue() const { return expect_continue_; }

 private:
  enum class Phase { kRequestLine, kHeaders, kBody, kChunkSize, kChunkData, kChunkEnd, kTrailers };

  bool fail(int status, std::string message);
  bool complete();
  bool on_line(std::string_view line);
  bool on_request_line(std::string_view line);
  bool on_field_line(std::string_view line, bool trailer);
  bool on_headers_done();
  bool on_chunk_size_line(std::string_view line);
  // Fails with the right status if the line being accumulated can no longer fit.
  bool check_line_limit();

  Limits limits_;
  State state_ = State::kIncomplete;
  Phase phase_ = Phase::kRequestLine;
  Request request_;
  std::string line_;             // the current line, accumulated across feed() calls
  std::string authority_;        // of an absolute-form target, else empty
  std::string origin_form_;      // an absolute-form target's path and query
  std::size_t head_bytes_ = 0;   // bytes of request line, fields and trailers processed so far
  std::size_t field_count_ = 0;  // header fields plus trailer fields
  std::size_t remaining_ = 0;    // body bytes still expected (Content-Length or current chunk)
  bool started_ = false;
  bool headers_complete_ = false;
  bool expect_continue_ = false;
  int error_status_ = 0;
  std::string error_message_;
};

}  // namespace scanplan::http
