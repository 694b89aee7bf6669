#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "http/request.hpp"
#include "http/response.hpp"

namespace scanplan::http {

struct WebSocketHandshakeOptions {
  // Origins (e.g. "http://127.0.0.1:8080") allowed to connect, compared case-insensitively.
  // Empty accepts any. A request without Origin is always accepted: only browsers send it, and
  // the check exists to stop other sites' pages from using a browser's credentials.
  std::vector<std::string> allowed_origins;
};

// Why an upgrade request cannot become a WebSocket: the status and REST error code to answer
// with, and a message for the client.
struct WebSocketHandshakeError {
  int status = 400;
  std::string code;
  std::string message;
};

// Checks an opening handshake against RFC 6455 §4.2.1: GET over HTTP/1.1, "Upgrade: websocket",
// a Connection field with the "upgrade" token, "Sec-WebSocket-Version: 13" and exactly one
// Sec-WebSocket-Key that is the base64 form of 16 bytes. A wrong method answers 405, a wrong
// version 426 (with Sec-WebSocket-Version: 13 so the client can retry), a refused Origin 403, and
// anything else 400. nullopt when the request is acceptable.
std::optional<WebSocketHandshakeError> check_websocket_handshake(
    const Request& request, const WebSocketHandshakeOptions& options = {});

// Sec-WebSocket-Accept for a client key: base64(SHA-1(key + the RFC 6455 GUID)).
// Throws std::runtime_error if OpenSSL cannot compute the digest.
std::string websocket_accept_key(std::string_view client_key);

// The answer to an upgrade request: 101 Switching Protocols with on_upgrade set when the request
// passes check_websocket_handshake, else that error as a JSON response. No subprotocol and no
// extension (in particular not permessage-deflate) is ever agreed to. Throws
// std::invalid_argument when on_upgrade is empty.
Response websocket_handshake_response(const Request& request, UpgradeHandler on_upgrade,
                                      const WebSocketHandshakeOptions& options = {});

}  // namespace scanplan::http
