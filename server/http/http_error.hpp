#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace scanplan::http {

// Thrown by a handler to answer with a specific JSON error instead of a generic 500, e.g.
// `throw HttpError(400, "bad_request", "query parameter 'x' must be a number, got 'abc'")`.
// The message is sent to the client, so it must be written for the client.
class HttpError : public std::runtime_error {
 public:
  HttpError(int status, std::string code, const std::string& message)
      : std::runtime_error(message), status_(status), code_(std::move(code)) {}

  int status() const { return status_; }
  const std::string& code() const { return code_; }

 private:
  int status_;
  std::string code_;
};

}  // namespace scanplan::http
