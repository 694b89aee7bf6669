#include "tcp_connect.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "http_client_error.hpp"

namespace scanplan::cli {
namespace {

// strerror's "Connection refused" reads better mid-sentence as "connection refused".
std::string reason(int err) {
  std::string s = std::strerror(err);
  if (!s.empty()) s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
  return s;
}

std::string hint(int err) {
  switch (err) {
    case ECONNREFUSED:
      return " — is scanplan-server running?";
    case EAGAIN:
    case ETIMEDOUT:
    case EINPROGRESS:
    case EHOSTUNREACH:
    case ENETUNREACH:
      return " — is the address right and the network up?";
    default:
      return "";
  }
}

}  // namespace

http::UniqueFd connect_tcp(const ServerUrl& url, std::chrono::milliseconds timeout) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(url.host.c_str(), url.port.c_str(), &hints, &found); rc != 0) {
    throw HttpClientError(HttpClientError::Kind::kUnreachable, "cannot reach " + url.base +
                                                                   ": cannot resolve '" + url.host +
                                                                   "' (" + gai_strerror(rc) + ")");
  }
  std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> addrs(found, freeaddrinfo);
  int last_error = EHOSTUNREACH;
  for (addrinfo* a = found; a; a = a->ai_next) {
    http::UniqueFd sock(::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol));
    if (!sock) {
      last_error = errno;
      continue;
    }
    // On Linux SO_SNDTIMEO also bounds connect(), which then fails with EINPROGRESS.
    timeval tv{static_cast<time_t>(timeout.count() / 1000),
               static_cast<suseconds_t>((timeout.count() % 1000) * 1000)};
    setsockopt(sock.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(sock.get(), SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    // Requests and control frames are small; waiting to coalesce them only adds latency.
    const int one = 1;
    setsockopt(sock.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    if (::connect(sock.get(), a->ai_addr, a->ai_addrlen) == 0) return sock;
    last_error = errno;
  }
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", static_cast<double>(timeout.count()) / 1000.0);
  const std::string why = last_error == EINPROGRESS || last_error == EAGAIN
                              ? "connection timed out after " + std::string(seconds) + " s"
                              : reason(last_error);
  throw HttpClientError(HttpClientError::Kind::kUnreachable,
                        "cannot reach " + url.base + ": " + why + hint(last_error));
}

}  // namespace scanplan::cli
