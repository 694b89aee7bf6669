#pragma once

#include <chrono>

#include "http/unique_fd.hpp"
#include "server_url.hpp"

namespace scanplan::cli {

// A blocking TCP connection to the server, with `timeout` for the connect itself and as the
// socket's send and receive timeouts. Throws HttpClientError (kind kUnreachable) with a message
// an operator can act on, e.g. "cannot reach http://127.0.0.1:8080: connection refused — is
// scanplan-server running?".
http::UniqueFd connect_tcp(const ServerUrl& url, std::chrono::milliseconds timeout);

}  // namespace scanplan::cli
