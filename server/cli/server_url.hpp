#pragma once

#include <string>

namespace scanplan::cli {

// Where scanplan-server listens, from a --server URL such as "http://127.0.0.1:8080". Only
// http:// (the server listens on loopback or a local network); a trailing path is ignored.
struct ServerUrl {
  std::string base;  // as given, without a trailing '/', for messages
  std::string host;
  std::string port;  // "80" when the URL names none
};

// Throws HttpClientError (kind kBadUrl) with a message naming what is wrong.
ServerUrl parse_server_url(const std::string& url);

}  // namespace scanplan::cli
