#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace scanplan {

// What free text the server keeps and shows to every operator may hold (issue 16): a robot id
// ends up in file names, log lines, DDS keys and the page; a reason or a note in the session
// and on every screen. Each check returns why `text` is refused, naming `field`, or nothing.

// A robot id: 1 to 64 of A–Z, a–z, 0–9, '_', '-', '.' (ROS 2 names and DDS keys need no more).
std::optional<std::string> robot_id_problem(std::string_view text,
                                            std::string_view field = "robot");

// One line of text (a name) or prose (newlines and tabs allowed): valid UTF-8 without other
// control characters, at most `max_bytes`.
enum class TextKind { kLine, kProse };
std::optional<std::string> text_problem(std::string_view text, std::string_view field,
                                        std::size_t max_bytes, TextKind kind);

// Text from a peer that is shown rather than refused (a robot's status message over DDS): control
// characters but newline and tab become spaces, invalid UTF-8 becomes U+FFFD, and it is cut to
// at most `max_bytes` on a character boundary.
std::string cleaned_text(std::string_view text, std::size_t max_bytes);

}  // namespace scanplan
