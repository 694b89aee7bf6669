#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "http/request.hpp"

namespace scanplan::http {

// Takes over a socket after a 101 Switching Protocols response (e.g. for WebSocket). Receives
// ownership of the file descriptor (still non-blocking) and any bytes the client sent after the
// upgrade request, which already belong to the new protocol.
using UpgradeHandler = std::function<void(int fd, std::string buffered)>;

struct Response {
  int status = 200;
  std::vector<Header> headers;  // framing fields (Content-Length, Transfer-Encoding) are ignored
  std::string body;
  // A body shared with whoever made it (the map's encoding, a layer image), sent without a copy
  // (OutputQueue); used instead of `body` when set. `shared_body` lives as long as the owner.
  std::shared_ptr<const void> shared_owner;
  std::string_view shared_body;
  // Honoured only with status 101: the server writes the response, then hands the socket over.
  UpgradeHandler on_upgrade;

  // Body is j serialized compactly; invalid UTF-8 in strings is replaced rather than thrown on,
  // because strings often echo client input.
  static Response json(int status, const nlohmann::json& j);
  // The REST error shape: {"error":{"code":code,"message":message}}.
  static Response error(int status, std::string_view code, std::string_view message);
  static Response bytes(std::string body, std::string_view content_type);
  static Response shared(std::shared_ptr<const std::string> body, std::string_view content_type);
  static Response shared(std::shared_ptr<const std::vector<std::uint8_t>> body,
                         std::string_view content_type);
  // The body as sent: the shared one when set.
  std::string_view body_bytes() const;

  // Replaces any field of the same name (case-insensitive).
  void set_header(std::string_view name, std::string_view value);
  std::optional<std::string_view> header(std::string_view name) const;
};

// The response as bytes on the wire: status line, fields, Date, Content-Length (omitted for 1xx,
// 204 and 304, which cannot have a body), "Connection: close" unless keep_alive, then the body
// unless head_request. Header names that are not tokens are dropped and control characters in
// values become spaces, so a handler echoing client input cannot split the response.
std::string serialize(const Response& response, bool keep_alive, bool head_request);
// The same without the body, and whether the body follows it on the wire, so that a server can
// queue a shared body without copying it.
std::string serialize_head(const Response& response, bool keep_alive);
bool sends_body(const Response& response, bool head_request);

}  // namespace scanplan::http
