#pragma once

// What the point-cloud readers (PLY, PCD, 3DTK) share for the text parts of their files:
// reading lines, splitting and parsing numbers strictly, and error messages that name the
// source and line. Internal to scanplan_core; not an installed header.

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "scanplan/io/scan_file.hpp"

namespace scanplan::text_scan {

// Throws a ScanFileError "<source>: <what>".
[[noreturn]] inline void fail(const std::string& source, const std::string& what) {
  throw ScanFileError(source + ": " + what);
}

// Throws a ScanFileError "<source>: line <line>: <what>".
[[noreturn]] inline void fail_line(const std::string& source, std::size_t line,
                                   const std::string& what) {
  fail(source, "line " + std::to_string(line) + ": " + what);
}

// Reads a file's bytes a line at a time, counting the lines so that messages can name them.
// The PLY and PCD parsers derive from it and read binary bodies by moving `pos_` themselves.
class LineReader {
 public:
  // `source` names the file in messages and must outlive the reader.
  LineReader(std::string_view bytes, const std::string& source) : bytes_(bytes), source_(source) {}

  // The next line from `pos_` without its line break ("\n" or "\r\n"); false at the end of
  // the bytes.
  bool next_line(std::string_view& line) {
    if (pos_ >= bytes_.size()) return false;
    const std::size_t end = bytes_.find('\n', pos_);
    const std::size_t stop = end == std::string_view::npos ? bytes_.size() : end;
    line = bytes_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end == std::string_view::npos ? bytes_.size() : end + 1;
    ++line_;
    return true;
  }

  // The number of the line `next_line` gave last, from 1; 0 before the first.
  std::size_t line_number() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const { text_scan::fail(source_, what); }
  [[noreturn]] void fail_line(std::size_t line, const std::string& what) const {
    text_scan::fail_line(source_, line, what);
  }

 protected:
  std::string_view bytes_;
  const std::string& source_;
  std::size_t pos_ = 0;   // the first byte not yet read
  std::size_t line_ = 0;  // lines read so far
};

// The blank- or tab-separated words of a line.
inline std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t') ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

// The whole of `s` as an integer, with an optional leading '+'; false if it is anything else
// or out of T's range.
template <typename T>
bool parse_int(std::string_view s, T& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size();
}

// The whole of `s` as a number, with an optional leading '+'; "nan" and "inf" are numbers too.
inline bool parse_double(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  if (p != s.data() + s.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `out` alone here; strtod gives ±HUGE_VAL or 0 as a text reader (3DTK's
    // own among them) would, and the non-finite filter then decides.
    out = std::strtod(std::string(s).c_str(), nullptr);
    return true;
  }
  return ec == std::errc();
}

// Appends the shortest text that reads back as `v`.
inline void append_text(std::string& out, float v) {
  std::array<char, 32> buf;
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  out.append(buf.data(), ec == std::errc() ? end : buf.data());
}

}  // namespace scanplan::text_scan
