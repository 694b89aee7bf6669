#pragma once

#include <cstddef>
#include <string_view>

namespace scanplan::http {

// Whether bytes are well-formed UTF-8 (RFC 3629): no overlong forms, no UTF-16 surrogates, nothing
// above U+10FFFF. WebSocket text must be valid UTF-8 (RFC 6455 §8.1), and browsers fail the whole
// connection over one bad byte, so text is checked before it is sent or accepted.
bool is_valid_utf8(std::string_view bytes);

// The length of the well-formed UTF-8 sequence that starts at bytes[at] (1 to 4), or 0 when none
// does there (the same rules as is_valid_utf8).
std::size_t utf8_sequence_length(std::string_view bytes, std::size_t at);

// The longest prefix of bytes, at most max_bytes long, that does not end inside a multi-byte
// sequence; for shortening already valid text without producing invalid text.
std::size_t utf8_prefix_length(std::string_view bytes, std::size_t max_bytes);

}  // namespace scanplan::http
