#pragma once

#include <string>

namespace scanplan::cli {

// What the terminal operator's commands (status, candidates, approve, reject, watch) exit with,
// so that scripts can tell a server that is down from a token that is wrong without reading
// messages. Command-line mistakes exit with CLI11's codes (100 and above).
enum class ExitCode : int {
  kOk = 0,
  kFailure = 1,          // anything not listed: a bad answer, a broken local file
  kUnreachable = 2,      // no connection to the server, or it was lost (watch without reconnect)
  kBadToken = 3,         // 401: no token, or the server does not know it
  kForbidden = 4,        // 403: a viewer token asked for an operator action
  kNotFound = 5,         // 404: e.g. a candidate that is not in the current plan
  kConflict = 6,         // 409: e.g. a candidate no longer proposed, or the robot still moving
  kServerFailure = 7,    // 5xx: e.g. 503, no robot bridge connected
  kDeclined = 8,         // the operator answered no at the confirmation prompt
  kBadRequest = 9,       // 400 and other 4xx: the server names what was wrong
  kRefusedByRobot = 10,  // approve: the robot answered that it cannot go there
  kNoAnswer = 11,        // approve: the robot did not answer within --wait
};

inline int to_int(ExitCode c) {
  return static_cast<int>(c);
}

// The table above for --help footers.
std::string exit_code_help();

}  // namespace scanplan::cli
