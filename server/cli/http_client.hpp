#pragma once

#include <chrono>
#include <map>
#include <string>

#include "http_client_error.hpp"
#include "server_url.hpp"

namespace scanplan::cli {

struct HttpResult {
  int status = 0;
  std::map<std::string, std::string> headers;  // names lower-cased
  std::string body;
};

// A small blocking HTTP/1.1 client for the CLI's talks with scanplan-server: one request per
// connection, Content-Length or chunked responses. Only http:// (the server listens on
// loopback or a local network).
class HttpClient {
 public:
  // `base` like "http://127.0.0.1:8080"; throws HttpClientError for anything else.
  explicit HttpClient(const std::string& base,
                      std::chrono::milliseconds timeout = std::chrono::seconds(30));

  // Throws HttpClientError when no HTTP answer arrives; any status is an answer.
  HttpResult request(const std::string& method, const std::string& path,
                     const std::map<std::string, std::string>& headers = {},
                     const std::string& body = {}) const;
  const std::string& base() const { return url_.base; }

 private:
  ServerUrl url_;
  std::chrono::milliseconds timeout_;
};

}  // namespace scanplan::cli
