#include "websocket_client.hpp"

#include <openssl/evp.h>
#include <openssl/rand.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "http/websocket_handshake.hpp"
#include "http_client_error.hpp"
#include "tcp_connect.hpp"

namespace scanplan::cli {
namespace {

using http::WebSocketMessage;
using http::WebSocketOpcode;
using Clock = std::chrono::steady_clock;

constexpr unsigned char kMaskBit = 0x80;
// An answer head longer than this is not scanplan-server's (its own limit for requests is 16 KiB).
constexpr std::size_t kMaxHeadBytes = 16 * 1024;
constexpr std::size_t kMaxErrorBodyBytes = 64 * 1024;

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Whether a comma-separated field value lists token (case-insensitively), as Connection does.
bool lists(std::string_view value, std::string_view token) {
  while (!value.empty()) {
    const auto comma = value.find(',');
    if (iequals(trim(value.substr(0, comma)), token)) return true;
    if (comma == std::string_view::npos) break;
    value.remove_prefix(comma + 1);
  }
  return false;
}

HttpClientError protocol_error(const std::string& server, const std::string& what) {
  return HttpClientError(HttpClientError::Kind::kNotHttp,
                         server + " did not open a WebSocket as RFC 6455 requires: " + what);
}

HttpClientError lost(const std::string& server, const std::string& what) {
  return HttpClientError(HttpClientError::Kind::kNoAnswer,
                         "lost the connection to " + server + ": " + what);
}

void send_all(int fd, std::string_view bytes, const std::string& server) {
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw lost(server, errno == EAGAIN ? "sending timed out" : std::strerror(errno));
    }
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

std::array<std::uint8_t, 4> random_mask() {
  std::array<std::uint8_t, 4> mask{};
  // RFC 6455 §5.3: the masking key must not be predictable by the network in between.
  if (RAND_bytes(mask.data(), static_cast<int>(mask.size())) != 1) {
    throw std::runtime_error("no randomness for a WebSocket masking key (OpenSSL RAND_bytes)");
  }
  return mask;
}

// A client's close frame: the server's encoder builds the payload (the code, the reason trimmed to
// fit and dropped if not UTF-8) and the client's encoder masks it. An invalid code becomes 1000.
std::string client_close_frame(std::uint16_t code, std::string_view reason) {
  if (!http::is_valid_close_code(code)) code = http::websocket_close::kNormal;
  const std::string server_form = http::encode_websocket_close(code, reason);
  // The payload is at most 125 bytes, so the server frame's header is its first 2 bytes.
  return encode_client_frame(WebSocketOpcode::kClose, std::string_view(server_form).substr(2),
                             random_mask());
}

}  // namespace

std::string encode_client_frame(WebSocketOpcode opcode, std::string_view payload,
                                std::array<std::uint8_t, 4> mask) {
  std::string out;
  out.reserve(14 + payload.size());
  // The server's header writer knows the length encodings; a client frame differs only in the
  // mask bit and the key after the length.
  http::append_websocket_frame_header(out, opcode, payload.size());
  out[1] = static_cast<char>(static_cast<unsigned char>(out[1]) | kMaskBit);
  for (std::uint8_t k : mask) out.push_back(static_cast<char>(k));
  const std::size_t start = out.size();
  out.append(payload);
  for (std::size_t i = 0; i < payload.size(); ++i) {
    out[start + i] = static_cast<char>(static_cast<unsigned char>(out[start + i]) ^ mask[i & 3]);
  }
  return out;
}

std::string websocket_upgrade_request(const ServerUrl& url, const std::string& path,
                                      const std::string& key,
                                      const std::map<std::string, std::string>& headers) {
  std::string req = "GET " + path + " HTTP/1.1\r\nHost: " + url.host + ":" + url.port +
                    "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: " + key +
                    "\r\nSec-WebSocket-Version: 13\r\n";
  for (const auto& [k, v] : headers) req += k + ": " + v + "\r\n";
  req += "\r\n";
  return req;
}

int check_upgrade_answer(std::string_view head, const std::string& key, const std::string& server) {
  if (head.substr(0, 7) != "HTTP/1." || head.size() < 12) {
    throw HttpClientError(HttpClientError::Kind::kNotHttp,
                          "the answer from " + server + " is not HTTP");
  }
  const int status = std::atoi(std::string(head.substr(9, 3)).c_str());
  if (status != 101) return status;
  bool upgrade = false, connection = false;
  std::string accept;
  std::size_t pos = head.find("\r\n");
  while (pos != std::string_view::npos && pos + 2 < head.size()) {
    pos += 2;
    const auto eol = head.find("\r\n", pos);
    const std::string_view line = head.substr(pos, eol - pos);
    pos = eol;
    const auto colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string_view name = trim(line.substr(0, colon));
    const std::string_view value = trim(line.substr(colon + 1));
    if (iequals(name, "Upgrade")) upgrade = upgrade || iequals(value, "websocket");
    if (iequals(name, "Connection")) connection = connection || lists(value, "upgrade");
    if (iequals(name, "Sec-WebSocket-Accept")) accept = std::string(value);
    if (iequals(name, "Sec-WebSocket-Extensions")) {
      throw protocol_error(server, "it agreed to an extension (" + std::string(value) +
                                       ") that this client never offered");
    }
  }
  if (!upgrade) throw protocol_error(server, "the 101 answer lacks 'Upgrade: websocket'");
  if (!connection) throw protocol_error(server, "the 101 answer lacks 'Connection: Upgrade'");
  if (accept.empty()) throw protocol_error(server, "the 101 answer lacks Sec-WebSocket-Accept");
  if (accept != http::websocket_accept_key(key)) {
    throw protocol_error(server, "Sec-WebSocket-Accept '" + accept +
                                     "' does not match the key sent (is a proxy in between?)");
  }
  return status;
}

std::string random_websocket_key() {
  unsigned char bytes[16];
  if (RAND_bytes(bytes, sizeof bytes) != 1) {
    throw std::runtime_error("no randomness for a Sec-WebSocket-Key (OpenSSL RAND_bytes)");
  }
  unsigned char encoded[25];  // 4 * ceil(16 / 3) + NUL
  const int n = EVP_EncodeBlock(encoded, bytes, sizeof bytes);
  return std::string(reinterpret_cast<const char*>(encoded), static_cast<std::size_t>(n));
}

WebSocketClient::WebSocketClient(http::UniqueFd fd, std::string server,
                                 std::size_t max_message_bytes)
    : fd_(std::move(fd)),
      server_(std::move(server)),
      parser_(max_message_bytes, http::WebSocketFrameSender::kServer),
      last_heard_(Clock::now()) {}

WebSocketClient WebSocketClient::connect(const ServerUrl& url, const std::string& path,
                                         const std::map<std::string, std::string>& headers,
                                         std::chrono::milliseconds timeout,
                                         std::size_t max_message_bytes) {
  http::UniqueFd fd = connect_tcp(url, timeout);
  const std::string key = random_websocket_key();
  send_all(fd.get(), websocket_upgrade_request(url, path, key, headers), url.base);

  // The answer's head, read until the blank line; the socket's receive timeout bounds each read.
  std::string raw;
  std::size_t head_end = std::string::npos;
  char buf[16384];
  while ((head_end = raw.find("\r\n\r\n")) == std::string::npos) {
    if (raw.size() > kMaxHeadBytes) {
      throw HttpClientError(HttpClientError::Kind::kNotHttp,
                            "the answer from " + url.base + " has an overlong head");
    }
    // EINTR is not retried: a Ctrl-C while the server is slow to answer ends the attempt.
    const ssize_t n = ::recv(fd.get(), buf, sizeof buf, 0);
    if (n < 0) {
      throw HttpClientError(
          HttpClientError::Kind::kNoAnswer,
          "no answer from " + url.base + ": " +
              (errno == EAGAIN ? std::string("timed out") : std::strerror(errno)));
    }
    if (n == 0) {
      throw HttpClientError(HttpClientError::Kind::kNoAnswer,
                            url.base + " closed the connection without answering the upgrade");
    }
    raw.append(buf, static_cast<std::size_t>(n));
  }
  const int status =
      check_upgrade_answer(std::string_view(raw).substr(0, head_end + 2), key, url.base);
  if (status != 101) {
    // The body says why (the server's JSON error); it ends at Content-Length or at EOF.
    std::string body = raw.substr(head_end + 4);
    std::size_t length = kMaxErrorBodyBytes;
    const std::string lower_head = [&] {
      std::string s = raw.substr(0, head_end);
      for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      return s;
    }();
    if (const auto at = lower_head.find("\r\ncontent-length:"); at != std::string::npos) {
      length = std::min<std::size_t>(kMaxErrorBodyBytes,
                                     std::strtoul(lower_head.c_str() + at + 17, nullptr, 10));
    }
    while (body.size() < length) {
      const ssize_t n = ::recv(fd.get(), buf, sizeof buf, 0);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      body.append(buf, static_cast<std::size_t>(n));
    }
    body.resize(std::min(body.size(), length));
    throw WebSocketRefusedError(status, std::move(body));
  }
  WebSocketClient client(std::move(fd), url.base, max_message_bytes);
  client.buffer_ = raw.substr(head_end + 4);  // frames that came with the answer
  return client;
}

std::optional<WebSocketMessage> WebSocketClient::parse_buffered() {
  while (buffer_pos_ < buffer_.size()) {
    buffer_pos_ += parser_.feed(std::string_view(buffer_).substr(buffer_pos_));
    if (parser_.state() == http::WebSocketFrameParser::State::kError) {
      // Fail the connection (RFC 6455 §7.1.7): a close with the parser's code, then no waiting
      // for an answer from a peer that does not follow the protocol.
      const std::string why = parser_.error_message();
      try {
        send_all(fd_.get(), client_close_frame(parser_.error_code(), why), server_);
      } catch (const std::exception&) {
        // The connection is being dropped anyway.
      }
      fd_.reset();
      throw HttpClientError(HttpClientError::Kind::kNotHttp,
                            server_ + " broke the WebSocket protocol: " + why);
    }
    if (parser_.state() != http::WebSocketFrameParser::State::kComplete) continue;
    WebSocketMessage m = parser_.take();
    if (m.opcode == WebSocketOpcode::kPing) {
      send(WebSocketOpcode::kPong, m.payload);
      continue;
    }
    if (m.opcode == WebSocketOpcode::kPong) continue;
    return m;
  }
  buffer_.clear();
  buffer_pos_ = 0;
  return std::nullopt;
}

std::optional<WebSocketMessage> WebSocketClient::receive(std::chrono::milliseconds wait) {
  if (!fd_) throw lost(server_, "the connection is closed");
  const auto deadline = Clock::now() + wait;
  for (;;) {
    if (auto m = parse_buffered()) {
      if (m->opcode == WebSocketOpcode::kClose) {
        // Echo the code (RFC 6455 §5.5.1) unless this was the answer to our own close.
        if (!close_sent_) {
          try {
            send_all(fd_.get(), client_close_frame(m->close_code, {}), server_);
          } catch (const std::exception&) {
            // The server may already have closed its side; nothing is lost.
          }
          close_sent_ = true;
        }
        fd_.reset();
      }
      return m;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return std::nullopt;
    pollfd p{fd_.get(), POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) return std::nullopt;
    if (ready < 0) throw lost(server_, std::strerror(errno));
    if (ready == 0) return std::nullopt;
    char buf[65536];
    const ssize_t n = ::recv(fd_.get(), buf, sizeof buf, 0);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) {
      const std::string why = std::strerror(errno);
      fd_.reset();
      throw lost(server_, why);
    }
    if (n == 0) {
      fd_.reset();
      throw lost(server_, "the server closed it without a WebSocket close frame");
    }
    last_heard_ = Clock::now();
    buffer_.append(buf, static_cast<std::size_t>(n));
  }
}

void WebSocketClient::send(WebSocketOpcode opcode, std::string_view payload) {
  if (!fd_) throw lost(server_, "the connection is closed");
  send_all(fd_.get(), encode_client_frame(opcode, payload, random_mask()), server_);
}

void WebSocketClient::close(std::uint16_t code, std::string_view reason,
                            std::chrono::milliseconds wait) {
  if (!fd_) return;
  try {
    if (!close_sent_) {
      close_sent_ = true;
      send_all(fd_.get(), client_close_frame(code, reason), server_);
    }
    const auto deadline = Clock::now() + wait;
    while (fd_ && Clock::now() < deadline) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      const auto m = receive(left);
      if (m && m->opcode == WebSocketOpcode::kClose) break;
    }
  } catch (const std::exception&) {
    // Closing anyway; an error here only means the server went first.
  }
  fd_.reset();
}

}  // namespace scanplan::cli
