#include "http_client.hpp"

#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "tcp_connect.hpp"

namespace scanplan::cli {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

HttpClient::HttpClient(const std::string& base, std::chrono::milliseconds timeout)
    : url_(parse_server_url(base)), timeout_(timeout) {}

HttpResult HttpClient::request(const std::string& method, const std::string& path,
                               const std::map<std::string, std::string>& headers,
                               const std::string& body) const {
  const http::UniqueFd sock = connect_tcp(url_, timeout_);
  const std::string& base = url_.base;
  std::string req = method + " " + path + " HTTP/1.1\r\nHost: " + url_.host + ":" + url_.port +
                    "\r\nConnection: close\r\nContent-Length: " + std::to_string(body.size()) +
                    "\r\n";
  for (const auto& [k, v] : headers) req += k + ": " + v + "\r\n";
  req += "\r\n";
  req += body;
  for (std::size_t sent = 0; sent < req.size();) {
    const ssize_t n = ::send(sock.get(), req.data() + sent, req.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw HttpClientError(HttpClientError::Kind::kNoAnswer,
                            "sending to " + base + " failed: " + std::strerror(errno));
    }
    sent += static_cast<std::size_t>(n);
  }

  std::string raw;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::recv(sock.get(), buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw HttpClientError(
          HttpClientError::Kind::kNoAnswer,
          "no answer from " + base + ": " +
              (errno == EAGAIN ? std::string("timed out") : std::strerror(errno)));
    }
    if (n == 0) break;
    raw.append(buf, static_cast<std::size_t>(n));
  }

  const auto head_end = raw.find("\r\n\r\n");
  if (head_end == std::string::npos || raw.compare(0, 7, "HTTP/1.") != 0) {
    throw HttpClientError(HttpClientError::Kind::kNotHttp,
                          raw.empty() ? base + " closed the connection without an answer"
                                      : "the answer from " + base + " is not HTTP");
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
      if (eol == std::string::npos) {
        throw HttpClientError(HttpClientError::Kind::kNotHttp,
                              "broken chunked answer from " + base);
      }
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
