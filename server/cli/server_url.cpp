#include "server_url.hpp"

#include <algorithm>
#include <cctype>

#include "http_client_error.hpp"

namespace scanplan::cli {

ServerUrl parse_server_url(const std::string& url) {
  const std::string prefix = "http://";
  if (url.rfind(prefix, 0) != 0) {
    throw HttpClientError(
        HttpClientError::Kind::kBadUrl,
        "server URL '" + url + "' must start with http://, e.g. " + "http://127.0.0.1:8080");
  }
  std::string hostport = url.substr(prefix.size());
  if (const auto slash = hostport.find('/'); slash != std::string::npos) hostport.resize(slash);
  ServerUrl out;
  out.base = url;
  while (out.base.size() > prefix.size() && out.base.back() == '/') out.base.pop_back();
  // "[::1]:8080": the brackets keep the address's own colons apart from the port's.
  if (!hostport.empty() && hostport.front() == '[') {
    const auto close = hostport.find(']');
    if (close == std::string::npos) {
      throw HttpClientError(HttpClientError::Kind::kBadUrl,
                            "server URL '" + url + "' has an unclosed '['");
    }
    out.host = hostport.substr(1, close - 1);
    out.port = close + 1 < hostport.size() && hostport[close + 1] == ':'
                   ? hostport.substr(close + 2)
                   : "80";
  } else {
    const auto colon = hostport.rfind(':');
    out.host = colon == std::string::npos ? hostport : hostport.substr(0, colon);
    out.port = colon == std::string::npos ? "80" : hostport.substr(colon + 1);
  }
  if (out.host.empty()) {
    throw HttpClientError(HttpClientError::Kind::kBadUrl, "server URL '" + url + "' has no host");
  }
  const bool numeric = !out.port.empty() && out.port.size() <= 5 &&
                       std::all_of(out.port.begin(), out.port.end(),
                                   [](unsigned char c) { return std::isdigit(c) != 0; }) &&
                       std::stoi(out.port) <= 65535;
  if (!numeric) {
    throw HttpClientError(HttpClientError::Kind::kBadUrl,
                          "server URL '" + url + "' has no valid port (1-65535)");
  }
  return out;
}

}  // namespace scanplan::cli
