#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "http/unique_fd.hpp"
#include "http/websocket_frame.hpp"
#include "server_url.hpp"

namespace scanplan::cli {

// The server answered the upgrade request with an HTTP error instead of 101: the status and
// its body (the server's JSON error), so the caller can say what the server said.
class WebSocketRefusedError : public std::runtime_error {
 public:
  WebSocketRefusedError(int status, std::string body)
      : std::runtime_error("the server refused the WebSocket with HTTP " + std::to_string(status)),
        status_(status),
        body_(std::move(body)) {}
  int status() const { return status_; }
  const std::string& body() const { return body_; }

 private:
  int status_;
  std::string body_;
};

// One frame as a client must send it (RFC 6455 §5.3): FIN set, masked with `mask`, length in the
// shortest encoding. Throws std::invalid_argument as encode_websocket_frame does (a control
// payload over 125 bytes, kContinuation).
std::string encode_client_frame(http::WebSocketOpcode opcode, std::string_view payload,
                                std::array<std::uint8_t, 4> mask);

// The opening handshake's request (RFC 6455 §4.1) for `path` with the client's `key` (16 random
// bytes in base64) and extra header fields such as Authorization.
std::string websocket_upgrade_request(const ServerUrl& url, const std::string& path,
                                      const std::string& key,
                                      const std::map<std::string, std::string>& headers);

// Checks the head of the server's answer (status line and fields, up to the blank line) for a
// 101 that agrees to this key: "Upgrade: websocket", "Connection: Upgrade" and a
// Sec-WebSocket-Accept equal to websocket_accept_key(key). Returns the status; a status other
// than 101 is returned for the caller to read the body, a 101 that fails a check throws
// HttpClientError (kNotHttp) naming the check.
int check_upgrade_answer(std::string_view head, const std::string& key, const std::string& server);

// 16 bytes from OpenSSL's generator in base64: a Sec-WebSocket-Key.
std::string random_websocket_key();

// A WebSocket client on a blocking POSIX socket, for `scanplan watch`: connects, performs the
// opening handshake, then delivers the server's messages. Pings are answered and pongs dropped
// inside receive(), so callers see text, binary and close messages only.
class WebSocketClient {
 public:
  // Connects to url + path (path with its query) and completes the handshake within `timeout`.
  // Throws HttpClientError when the server cannot be reached or does not speak WebSocket, and
  // WebSocketRefusedError when it answers with an HTTP error (e.g. 401 for a wrong token).
  static WebSocketClient connect(const ServerUrl& url, const std::string& path,
                                 const std::map<std::string, std::string>& headers,
                                 std::chrono::milliseconds timeout,
                                 std::size_t max_message_bytes = 256u << 20);

  // Waits up to `wait` for the next message; nullopt when none completed in time or a signal
  // interrupted the wait (so a caller's stop flag is seen promptly). A close message is answered
  // with the same code and ends the connection. Throws HttpClientError (kNoAnswer) when the
  // connection drops without a close frame, and (kNotHttp) when the server breaks the protocol.
  std::optional<http::WebSocketMessage> receive(std::chrono::milliseconds wait);

  // Sends one masked frame. Throws HttpClientError (kNoAnswer) when the connection is gone.
  void send(http::WebSocketOpcode opcode, std::string_view payload);

  // Starts the closing handshake and waits up to `wait` for the server's close frame, then
  // closes the socket. Never throws: the connection is being given up either way.
  void close(std::uint16_t code, std::string_view reason, std::chrono::milliseconds wait);

  bool open() const { return static_cast<bool>(fd_); }
  // When the server was last heard from (any frame, pings included): a silent connection past
  // the server's ping interval is a dead one, which TCP alone may not notice for a long time.
  std::chrono::steady_clock::time_point last_heard() const { return last_heard_; }

 private:
  WebSocketClient(http::UniqueFd fd, std::string server, std::size_t max_message_bytes);
  // Runs the parser over buffered bytes; a complete message is returned (pings answered first).
  std::optional<http::WebSocketMessage> parse_buffered();

  http::UniqueFd fd_;
  std::string server_;
  http::WebSocketFrameParser parser_;
  std::string buffer_;  // received bytes not yet parsed, from buffer_pos_
  std::size_t buffer_pos_ = 0;
  bool close_sent_ = false;
  std::chrono::steady_clock::time_point last_heard_;
};

}  // namespace scanplan::cli
