#include "http/request.hpp"

#include "http/ascii.hpp"

namespace scanplan::http {

std::optional<std::string_view> Request::header(std::string_view name) const {
  for (const Header& h : headers) {
    if (ascii::iequals(h.name, name)) return std::string_view(h.value);
  }
  return std::nullopt;
}

bool Request::keep_alive() const {
  // Connection is a token list and may be split over several fields, so every element counts.
  bool close = false;
  bool keep = false;
  for (const Header& h : headers) {
    if (!ascii::iequals(h.name, "connection")) continue;
    ascii::for_each_list_element(h.value, [&](std::string_view token) {
      if (ascii::iequals(token, "close")) close = true;
      if (ascii::iequals(token, "keep-alive")) keep = true;
    });
  }
  if (close) return false;
  return version_minor >= 1 || keep;
}

}  // namespace scanplan::http
