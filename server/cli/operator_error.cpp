#include "operator_error.hpp"

#include <nlohmann/json.hpp>

namespace scanplan::cli {
namespace {

// The server's own words when the body is its JSON error, else a short piece of whatever came.
std::string server_message(std::string_view body) {
  const auto j = nlohmann::json::parse(body, nullptr, false);
  if (j.is_object() && j.contains("error") && j["error"].is_object()) {
    const auto& e = j["error"];
    if (e.contains("message") && e["message"].is_string()) return e["message"].get<std::string>();
    if (e.contains("code") && e["code"].is_string()) return e["code"].get<std::string>();
  }
  std::string s(body.substr(0, 200));
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s.empty() ? "no details given" : s;
}

}  // namespace

std::string exit_code_help() {
  return "Exit codes:\n"
         "  0  done\n"
         "  1  other failure (e.g. an answer not as documented)\n"
         "  2  server unreachable, or the connection lost (watch --no-reconnect)\n"
         "  3  token missing or refused (HTTP 401)\n"
         "  4  not allowed with this token (HTTP 403, e.g. a viewer token approving)\n"
         "  5  not found (HTTP 404, e.g. a candidate not in the current plan)\n"
         "  6  conflict (HTTP 409, e.g. a candidate no longer proposed, the robot still moving)\n"
         "  7  server-side failure (HTTP 5xx, e.g. 503 no robot bridge connected)\n"
         "  8  declined at the confirmation prompt\n"
         "  9  request refused as malformed (HTTP 400)\n"
         "  10 approve: the robot refused to go there\n"
         "  11 approve: the robot did not answer within --wait\n"
         "  100 and above: command-line usage errors";
}

OperatorError error_for_status(int status, std::string_view body, const std::string& action,
                               const std::string& server) {
  const std::string said = server_message(body);
  const std::string code = " (HTTP " + std::to_string(status) + ")";
  switch (status) {
    case 401:
      return {ExitCode::kBadToken,
              "the server refused the token" + code + ": " + said +
                  ". Give the operator or viewer token with --token or $SCANPLAN_TOKEN."};
    case 403:
      return {ExitCode::kForbidden, "cannot " + action + code + ": " + said};
    case 404:
      return {ExitCode::kNotFound, "cannot " + action + code + ": " + said};
    case 409:
      return {ExitCode::kConflict, "cannot " + action + code + ": " + said};
    default:
      break;
  }
  if (status >= 500) {
    return {ExitCode::kServerFailure, "cannot " + action + code + ": " + said};
  }
  if (status >= 400) {
    return {ExitCode::kBadRequest, "cannot " + action + code + ": " + said};
  }
  return {ExitCode::kFailure, "cannot " + action + ": " + server + " answered an unexpected " +
                                  std::to_string(status) + ": " + said};
}

OperatorError error_for_transport(const HttpClientError& e) {
  switch (e.kind()) {
    case HttpClientError::Kind::kBadUrl:
      return {ExitCode::kFailure, e.what()};
    case HttpClientError::Kind::kUnreachable:
    case HttpClientError::Kind::kNoAnswer:
      return {ExitCode::kUnreachable, e.what()};
    case HttpClientError::Kind::kNotHttp:
      return {ExitCode::kFailure, std::string(e.what()) + " — is that address scanplan-server?"};
  }
  return {ExitCode::kFailure, e.what()};
}

}  // namespace scanplan::cli
