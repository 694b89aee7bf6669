#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace scanplan::http {

// Decodes %XX escapes. Returns nullopt for a truncated or non-hex escape, because guessing what a
// client meant by "%zz" is how two components end up disagreeing about a path.
// plus_as_space applies the HTML form convention used in query strings.
std::optional<std::string> percent_decode(std::string_view in, bool plus_as_space);

// Splits "a=1&b=x%20y" into decoded pairs. A parameter without '=' gets an empty value; empty
// parameters are skipped. When a name repeats, the first value wins. nullopt on a bad escape.
std::optional<std::map<std::string, std::string>> parse_query(std::string_view query);

}  // namespace scanplan::http
