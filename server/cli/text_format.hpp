#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace scanplan::cli {

// Small number and time formats shared by the terminal operator's outputs.

// printf-style "%.<decimals>f" without locale surprises.
std::string fixed(double v, int decimals);
// "+0.31" / "-0.12": a correction's sign matters as much as its size.
std::string signed_fixed(double v, int decimals);
// "(12.3, -4.5)" in metres.
std::string position(double x, double y);
// "[########------------]  40%": plain ASCII so it survives any terminal and link.
std::string progress_bar(double fraction, int width = 20);

// Local wall-clock "HH:MM:SS" of a UTC ISO 8601 time as the server writes it
// ("2024-05-01T07:41:02Z"); nullopt when it is not in that form.
std::optional<std::string> local_clock_of(const std::string& iso_utc);
// Local "HH:MM:SS" of a time in nanoseconds since the epoch, and of now.
std::string local_clock_of_ns(std::uint64_t ns_since_epoch);
std::string local_clock_now();

}  // namespace scanplan::cli
