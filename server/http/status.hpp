#pragma once

#include <string_view>

namespace scanplan::http {

// The reason phrase for a status line ("Not Found"); a generic phrase for its class when unknown.
std::string_view reason_phrase(int status);

// The machine-readable code used in JSON error bodies for a status ("not_found"), so that errors
// produced by the transport (parser, limits, timeouts) look like those produced by handlers.
std::string_view error_code(int status);

}  // namespace scanplan::http
