#include "operator_client.hpp"

#include "operator_error.hpp"

namespace scanplan::cli {
namespace {

HttpClient make_http(const OperatorOptions& o) {
  try {
    return HttpClient(o.server, o.timeout());
  } catch (const HttpClientError& e) {
    throw error_for_transport(e);
  }
}

}  // namespace

OperatorClient::OperatorClient(const OperatorOptions& options)
    : http_(make_http(options)), token_(options.token) {
  if (token_.empty()) {
    throw OperatorError(ExitCode::kBadToken,
                        "no token: give the operator or viewer token with --token T or "
                        "$SCANPLAN_TOKEN (scanplan-server prints the operator's at start)");
  }
}

HttpResult OperatorClient::send(const std::string& method, const std::string& path,
                                const std::string& body, const std::string& action) const {
  std::map<std::string, std::string> headers{{"Authorization", "Bearer " + token_}};
  if (!body.empty()) headers["Content-Type"] = "application/json";
  HttpResult r;
  try {
    r = http_.request(method, path, headers, body);
  } catch (const HttpClientError& e) {
    throw error_for_transport(e);
  }
  if (r.status < 200 || r.status >= 300) {
    throw error_for_status(r.status, r.body, action, http_.base());
  }
  return r;
}

std::string OperatorClient::get_raw(const std::string& path, const std::string& action) const {
  return send("GET", path, {}, action).body;
}

nlohmann::json OperatorClient::get_json(const std::string& path, const std::string& action) const {
  const HttpResult r = send("GET", path, {}, action);
  nlohmann::json j = nlohmann::json::parse(r.body, nullptr, false);
  if (j.is_discarded()) {
    throw OperatorError(ExitCode::kFailure, "cannot " + action + ": the answer to GET " + path +
                                                " is not JSON — is " + http_.base() +
                                                " scanplan-server?");
  }
  return j;
}

std::optional<std::string> OperatorClient::get_bytes(const std::string& path,
                                                     const std::string& action) const {
  HttpResult r = send("GET", path, {}, action);
  if (r.status == 204) return std::nullopt;
  return std::move(r.body);
}

std::string OperatorClient::post(const std::string& path, const nlohmann::json& body,
                                 const std::string& action) const {
  return send("POST", path, body.is_null() ? std::string() : body.dump(), action).body;
}

std::string OperatorClient::del(const std::string& path, const nlohmann::json& body,
                                const std::string& action) const {
  return send("DELETE", path, body.is_null() ? std::string() : body.dump(), action).body;
}

std::string OperatorClient::put(const std::string& path, const nlohmann::json& body,
                                const std::string& action) const {
  return send("PUT", path, body.dump(), action).body;
}

}  // namespace scanplan::cli
