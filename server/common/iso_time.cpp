#include "common/iso_time.hpp"

#include <cstdio>
#include <ctime>

namespace scanplan {

std::string iso8601_utc(std::chrono::system_clock::time_point t, TimePrecision precision) {
  const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  if (precision == TimePrecision::kSeconds) return std::string(buf) + "Z";
  // to_time_t truncates towards zero, which for times before 1970 is not the floor: take the
  // milliseconds from the same truncated second so the two always agree.
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      t - std::chrono::system_clock::from_time_t(seconds))
                      .count();
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03dZ", buf, static_cast<int>(ms));
  return out;
}

std::string iso8601_utc_now(TimePrecision precision) {
  return iso8601_utc(std::chrono::system_clock::now(), precision);
}

}  // namespace scanplan
