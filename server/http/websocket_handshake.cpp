#include "http/websocket_handshake.hpp"

#include <openssl/evp.h>

#include <array>
#include <stdexcept>
#include <utility>

#include "http/ascii.hpp"

namespace scanplan::http {
namespace {

constexpr std::string_view kGuid = "258EAFA5-E914-47DA-95CA-C5AB0DC85B11";
constexpr std::string_view kVersion = "13";
// base64 of 16 bytes: 22 significant characters and "==" (RFC 4648 §4).
constexpr std::size_t kKeyChars = 24;

bool is_base64_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' ||
         c == '/';
}

bool is_16_byte_base64(std::string_view key) {
  if (key.size() != kKeyChars || key.substr(22) != "==") return false;
  for (std::size_t i = 0; i < 22; ++i) {
    if (!is_base64_char(key[i])) return false;
  }
  return true;
}

// Whether any field called name lists token; the fields are comma-separated lists and may repeat.
bool lists_token(const Request& request, std::string_view name, std::string_view token) {
  bool found = false;
  for (const Header& h : request.headers) {
    if (!ascii::iequals(h.name, name)) continue;
    ascii::for_each_list_element(h.value, [&](std::string_view element) {
      found = found || ascii::iequals(element, token);
    });
  }
  return found;
}

std::size_t count_fields(const Request& request, std::string_view name) {
  std::size_t n = 0;
  for (const Header& h : request.headers) n += ascii::iequals(h.name, name) ? 1 : 0;
  return n;
}

WebSocketHandshakeError bad(std::string message) {
  return {400, "bad_request", std::move(message)};
}

}  // namespace

std::optional<WebSocketHandshakeError> check_websocket_handshake(
    const Request& request, const WebSocketHandshakeOptions& options) {
  if (request.method != "GET") {
    return WebSocketHandshakeError{405, "method_not_allowed",
                                   "a WebSocket is opened with GET, not " + request.method};
  }
  if (request.version_minor < 1) {
    return bad("a WebSocket needs HTTP/1.1; the request used HTTP/1.0");
  }
  if (!lists_token(request, "Upgrade", "websocket")) {
    return bad("this endpoint is a WebSocket: send 'Upgrade: websocket' and 'Connection: Upgrade'");
  }
  if (!lists_token(request, "Connection", "upgrade")) {
    return bad("the Connection field must contain the 'Upgrade' token");
  }
  const std::optional<std::string_view> version = request.header("Sec-WebSocket-Version");
  if (count_fields(request, "Sec-WebSocket-Version") != 1 || !version ||
      ascii::trim_ows(*version) != kVersion) {
    return WebSocketHandshakeError{426, "upgrade_required",
                                   "unsupported WebSocket version '" +
                                       std::string(version.value_or("")) +
                                       "'; this server speaks version 13 (RFC 6455)"};
  }
  const std::optional<std::string_view> key = request.header("Sec-WebSocket-Key");
  if (!key) return bad("Sec-WebSocket-Key is missing");
  if (count_fields(request, "Sec-WebSocket-Key") != 1) {
    return bad("Sec-WebSocket-Key appears more than once");
  }
  if (!is_16_byte_base64(ascii::trim_ows(*key))) {
    return bad(
        "Sec-WebSocket-Key must be 16 random bytes in base64 (24 characters ending in '==')");
  }
  if (!options.allowed_origins.empty()) {
    if (const std::optional<std::string_view> origin = request.header("Origin")) {
      bool allowed = false;
      for (const std::string& o : options.allowed_origins) {
        allowed = allowed || ascii::iequals(ascii::trim_ows(*origin), o);
      }
      if (!allowed) {
        return WebSocketHandshakeError{
            403, "forbidden",
            "WebSocket connections from origin '" + std::string(*origin) + "' are not allowed"};
      }
    }
  }
  return std::nullopt;
}

std::string websocket_accept_key(std::string_view client_key) {
  std::string input(client_key);
  input += kGuid;
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int digest_size = 0;
  if (EVP_Digest(input.data(), input.size(), digest.data(), &digest_size, EVP_sha1(), nullptr) !=
      1) {
    throw std::runtime_error("cannot compute SHA-1 for the WebSocket handshake (OpenSSL failed)");
  }
  // EVP_EncodeBlock writes 4 characters per 3 input bytes, rounded up, plus a NUL.
  std::array<unsigned char, 4 * ((EVP_MAX_MD_SIZE + 2) / 3) + 1> encoded{};
  const int n = EVP_EncodeBlock(encoded.data(), digest.data(), static_cast<int>(digest_size));
  return std::string(reinterpret_cast<const char*>(encoded.data()), static_cast<std::size_t>(n));
}

Response websocket_handshake_response(const Request& request, UpgradeHandler on_upgrade,
                                      const WebSocketHandshakeOptions& options) {
  if (!on_upgrade) {
    throw std::invalid_argument(
        "websocket_handshake_response needs an upgrade handler to take the "
        "socket, e.g. WebSocketHub::adopt()");
  }
  if (const auto error = check_websocket_handshake(request, options)) {
    Response r = Response::error(error->status, error->code, error->message);
    if (error->status == 426) {
      r.set_header("Sec-WebSocket-Version", kVersion);
      r.set_header("Upgrade", "websocket");
    } else if (error->status == 405) {
      r.set_header("Allow", "GET");
    }
    return r;
  }
  Response r;
  r.status = 101;
  r.set_header("Upgrade", "websocket");
  r.set_header("Connection", "Upgrade");
  r.set_header("Sec-WebSocket-Accept",
               websocket_accept_key(ascii::trim_ows(*request.header("Sec-WebSocket-Key"))));
  r.on_upgrade = std::move(on_upgrade);
  return r;
}

}  // namespace scanplan::http
