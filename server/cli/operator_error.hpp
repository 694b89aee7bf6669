#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "exit_codes.hpp"
#include "http_client_error.hpp"

namespace scanplan::cli {

// A terminal-operator command that cannot do what was asked: a message for the person at the
// terminal and the exit code for scripts.
class OperatorError : public std::runtime_error {
 public:
  OperatorError(ExitCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

// The error for an HTTP answer with a 4xx/5xx status. `body` is the server's JSON error
// ({"error":{"code","message"}}), whose message is kept word for word since it names what was
// wrong; `action` says what was being done ("approve candidate 12"), `server` the URL.
OperatorError error_for_status(int status, std::string_view body, const std::string& action,
                               const std::string& server);

// The error for a request that got no answer at all (unreachable, timed out, not HTTP).
OperatorError error_for_transport(const HttpClientError& e);

}  // namespace scanplan::cli
