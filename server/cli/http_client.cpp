#include "http_client.hpp"

#include <netdb.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <memory>

namespace scanplan::cli {
namespace {

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

HttpClient::HttpClient(const std::string& base, std::chrono::milliseconds timeout)
    : base_(base), timeout_(timeout) {
  const std::string prefix = "http://";
  if (base.rfind(prefix, 0) != 0) {
    throw HttpClientError("server URL '" + base + "' must start with http://");
  }
  std::string hostport = base.substr(prefix.size());
  if (const auto slash = hostport.find('/'); slash != std::string::npos) hostport.resize(slash);
  const auto colon = hostport.rfind(':');
  host_ = colon == std::string::npos ? hostport : hostport.substr(0, colon);
  port_ = colon == std::string::npos ? "80" : hostport.substr(colon + 1);
  if (host_.empty() || port_.empty())
    throw HttpClientError("server URL '" + base + "' has no host");
}

HttpResult HttpClient::request(const std::string& method, const std::string& path,
                               const std::map<std::string, std::string>& headers,
                               const std::string& body) const {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(host_.c_str(), port_.c_str(), &hints, &found); rc != 0) {
    throw HttpClientError("cannot resolve " + host_ + ": " + gai_strerror(rc));
  }
  std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> addrs(found, freeaddrinfo);
  Fd sock;
  std::string last_error = "no address";
  for (addrinfo* a = found; a; a = a->ai_next) {
    sock.fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (sock.fd < 0) continue;
    timeval tv{static_cast<time_t>(timeout_.count() / 1000),
               static_cast<suseconds_t>((timeout_.count() % 1000) * 1000)};
    setsockopt(sock.fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(sock.fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    if (::connect(sock.fd, a->ai_addr, a->ai_addrlen) == 0) break;
    last_error = std::strerror(errno);
    ::close(sock.fd);
    sock.fd = -1;
  }
  if (sock.fd < 0) {
    throw HttpClientError("cannot reach the server at " + base_ + ": " + last_error +
                          " (is scanplan-server running?)");
  }

  std::string req = method + " " + path + " HTTP/1.1\r\nHost: " + host_ + ":" + port_ +
                    "\r\nConnection: close\r\nContent-Length: " + std::to_string(body.size()) +
                    "\r\n";
  for (const auto& [k, v] : headers) req += k + ": " + v + "\r\n";
  req += "\r\n";
  req += body;
  for (std::size_t sent = 0; sent < req.size();) {
    const ssize_t n = ::send(sock.fd, req.data() + sent, req.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw HttpClientError("sending to " + base_ + " failed: " + std::strerror(errno));
    sent += static_cast<std::size_t>(n);
  }

  std::string raw;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::recv(sock.fd, buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw HttpClientError("no answer from " + base_ + ": " +
                            (errno == EAGAIN ? std::string("timed out") : std::strerror(errno)));
    }
    if (n == 0) break;
    raw.append(buf, static_cast<std::size_t>(n));
  }

  const auto head_end = raw.find("\r\n\r\n");
  if (head_end == std::string::npos || raw.compare(0, 7, "HTTP/1.") != 0) {
    throw HttpClientError("the answer from " + base_ + " is not HTTP");
  }
  HttpResult r;
  r.status = std::atoi(raw.c_str() + 9);
  std::size_t pos = raw.find("\r\n") + 2;
  while (pos < head_end) {
    const auto eol = raw.find("\r\n", pos);
    const std::string line = raw.substr(pos, eol - pos);
    const auto colon = line.find(':');
    if (colon != std::string::npos) {
      std::string value = line.substr(colon + 1);
      value.erase(0, value.find_first_not_of(" \t"));
      r.headers[lower(line.substr(0, colon))] = value;
    }
    pos = eol + 2;
  }
  std::string payload = raw.substr(head_end + 4);
  if (lower(r.headers["transfer-encoding"]).find("chunked") != std::string::npos) {
    std::string out;
    std::size_t p = 0;
    for (;;) {
      const auto eol = payload.find("\r\n", p);
      if (eol == std::string::npos) throw HttpClientError("broken chunked answer from " + base_);
      const std::size_t size = std::stoul(payload.substr(p, eol - p), nullptr, 16);
      if (size == 0) break;
      out.append(payload, eol + 2, size);
      p = eol + 2 + size + 2;
    }
    payload = std::move(out);
  } else if (const auto it = r.headers.find("content-length"); it != r.headers.end()) {
    payload.resize(std::min<std::size_t>(payload.size(), std::stoul(it->second)));
  }
  r.body = std::move(payload);
  r.headers.erase("transfer-encoding");
  return r;
}

}  // namespace scanplan::cli
