#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "http_client.hpp"
#include "operator_options.hpp"

namespace scanplan::cli {

// The REST side of the terminal operator: requests with the bearer token, answers as JSON, and
// every failure as an OperatorError that says what to do (see operator_error.hpp).
class OperatorClient {
 public:
  // Throws OperatorError when there is no token or the URL is unusable.
  explicit OperatorClient(const OperatorOptions& options);

  // `action` names what is being done, for messages ("read the session", "approve candidate 12").
  nlohmann::json get_json(const std::string& path, const std::string& action) const;
  // The body as the server sent it, for --json.
  std::string get_raw(const std::string& path, const std::string& action) const;
  // nullopt for 204 No Content (e.g. a layer before the first scan).
  std::optional<std::string> get_bytes(const std::string& path, const std::string& action) const;
  // `body` null sends an empty body. Returns the answer's body as sent.
  std::string post(const std::string& path, const nlohmann::json& body,
                   const std::string& action) const;
  std::string put(const std::string& path, const nlohmann::json& body,
                  const std::string& action) const;
  std::string del(const std::string& path, const nlohmann::json& body,
                  const std::string& action) const;

  const std::string& server() const { return http_.base(); }
  const std::string& token() const { return token_; }

 private:
  HttpResult send(const std::string& method, const std::string& path, const std::string& body,
                  const std::string& action) const;

  HttpClient http_;
  std::string token_;
};

}  // namespace scanplan::cli
