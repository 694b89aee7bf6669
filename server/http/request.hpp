#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace scanplan::http {

struct Header {
  std::string name;
  std::string value;
};

// One parsed HTTP/1.x request. Produced by RequestParser, so its framing has been validated; the
// meaning of its contents (path, query, body) is still untrusted client input.
struct Request {
  std::string method;
  std::string target;  // the request-target exactly as received (origin-form, still encoded)
  std::string path;    // the path part of target, percent-decoded; may contain NUL or ".."
  std::map<std::string, std::string> query;  // percent-decoded, '+' as space; first value wins
  std::vector<Header> headers;               // in arrival order, names as sent
  std::string body;                          // de-chunked
  int version_minor = 1;                     // HTTP/1.<version_minor>
  std::string peer;                          // "address:port" of the client, when known

  // The first field with this name, compared case-insensitively.
  std::optional<std::string_view> header(std::string_view name) const;

  // Whether the client allows the connection to stay open after the response (RFC 9112 §9.3).
  bool keep_alive() const;
};

}  // namespace scanplan::http
