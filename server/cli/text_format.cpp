#include "text_format.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace scanplan::cli {
namespace {

std::string clock_of(std::time_t t) {
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%H:%M:%S", &tm);
  return buf;
}

}  // namespace

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  // "-0.0" reads as a sign that means something; it does not.
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

std::string signed_fixed(double v, int decimals) {
  std::string s = fixed(v, decimals);
  return s[0] == '-' ? s : "+" + s;
}

std::string position(double x, double y) {
  return "(" + fixed(x, 1) + ", " + fixed(y, 1) + ")";
}

std::string progress_bar(double fraction, int width) {
  const double f = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(std::lround(f * width));
  char pct[8];
  std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(std::lround(f * 100)));
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(width - filled), '-') + "] " + pct;
}

std::optional<std::string> local_clock_of(const std::string& iso_utc) {
  std::tm tm{};
  char z = 0;
  if (std::sscanf(iso_utc.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%c", &tm.tm_year, &tm.tm_mon,
                  &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &z) != 7 ||
      z != 'Z') {
    return std::nullopt;
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return clock_of(timegm(&tm));
}

std::string local_clock_of_ns(std::uint64_t ns_since_epoch) {
  return clock_of(static_cast<std::time_t>(ns_since_epoch / 1000000000ull));
}

std::string local_clock_now() {
  return clock_of(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now()));
}

}  // namespace scanplan::cli
