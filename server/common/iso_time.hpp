#pragma once

#include <chrono>
#include <string>

namespace scanplan {

// UTC in ISO 8601 with a Z, the one format the session, the API, the events and the CLI write
// times in: "2026-12-01T22:35:43Z", or with milliseconds "2026-12-01T22:35:43.123Z".
enum class TimePrecision { kSeconds, kMilliseconds };
std::string iso8601_utc(std::chrono::system_clock::time_point t,
                        TimePrecision precision = TimePrecision::kSeconds);
std::string iso8601_utc_now(TimePrecision precision = TimePrecision::kSeconds);

}  // namespace scanplan
