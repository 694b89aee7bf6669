#pragma once

#include <stdexcept>
#include <string>

namespace scanplan::cli {

// A request that got no HTTP answer. The kind lets the terminal operator say what to do about it
// (and pick its exit code) without parsing the message.
class HttpClientError : public std::runtime_error {
 public:
  enum class Kind {
    kBadUrl,       // the --server value cannot be used
    kUnreachable,  // no connection: refused, no route, unknown host, connect timed out
    kNoAnswer,     // connected, but the answer did not arrive (timeout, reset)
    kNotHttp,      // something answered, but not HTTP or not a WebSocket as agreed
  };

  HttpClientError(Kind kind, const std::string& message)
      : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

}  // namespace scanplan::cli
