#include "http/request_parser.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include "http/ascii.hpp"
#include "http/percent_encoding.hpp"

namespace scanplan::http {
namespace {

// While the request line is still arriving its target cannot be measured yet; the method, two
// spaces and the version fit comfortably in this much beyond the target limit.
constexpr std::size_t kRequestLineSlack = 64;
// A chunk size line is a few hex digits plus extensions nobody we talk to uses; anything longer
// is an attempt to make us buffer.
constexpr std::size_t kMaxChunkSizeLine = 4096;
// Pre-allocating the announced Content-Length in full would let clients reserve memory they
// never send; growing past this is amortised by std::string anyway.
constexpr std::size_t kMaxBodyReserve = 1 << 20;

bool is_target_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u > 0x20 && u < 0x7f && c != '#';
}

bool is_control(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && c != '\t') || u == 0x7f;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string limit_text(std::size_t bytes) {
  return std::to_string(bytes) + " bytes";
}

}  // namespace

RequestParser::RequestParser(Limits limits) : limits_(limits) {}

void RequestParser::reset() {
  state_ = State::kIncomplete;
  phase_ = Phase::kRequestLine;
  request_ = Request{};
  line_.clear();
  authority_.clear();
  head_bytes_ = 0;
  field_count_ = 0;
  remaining_ = 0;
  started_ = false;
  headers_complete_ = false;
  expect_continue_ = false;
  error_status_ = 0;
  error_message_.clear();
}

Request RequestParser::take() {
  if (state_ != State::kComplete) {
    throw std::logic_error("RequestParser::take() called before a request was complete");
  }
  Request request = std::move(request_);
  reset();
  return request;
}

std::size_t RequestParser::feed(std::string_view data) {
  std::size_t pos = 0;
  while (state_ == State::kIncomplete && pos < data.size()) {
    if (phase_ == Phase::kBody || phase_ == Phase::kChunkData) {
      const std::size_t n = std::min(remaining_, data.size() - pos);
      request_.body.append(data.data() + pos, n);
      pos += n;
      remaining_ -= n;
      if (remaining_ == 0) {
        if (phase_ == Phase::kBody) {
          complete();
        } else {
          phase_ = Phase::kChunkEnd;
        }
      }
      continue;
    }

    const std::size_t newline = data.find('\n', pos);
    const std::size_t end = newline == std::string_view::npos ? data.size() : newline + 1;
    const std::string_view piece = data.substr(pos, end - pos);
    line_.append(piece);
    pos = end;
    if (phase_ == Phase::kRequestLine && !started_) {
      started_ = piece.find_first_not_of("\r\n") != std::string_view::npos;
    }
    if (!check_line_limit() || newline == std::string_view::npos) continue;

    if (line_.size() < 2 || line_[line_.size() - 2] != '\r') {
      fail(400, "line ends in a bare LF; HTTP requires CRLF line endings");
      break;
    }
    if (phase_ == Phase::kRequestLine || phase_ == Phase::kHeaders || phase_ == Phase::kTrailers) {
      head_bytes_ += line_.size();
    }
    on_line(std::string_view(line_.data(), line_.size() - 2));
    line_.clear();
  }
  return pos;
}

bool RequestParser::fail(int status, std::string message) {
  state_ = State::kError;
  error_status_ = status;
  error_message_ = std::move(message);
  return false;
}

bool RequestParser::complete() {
  state_ = State::kComplete;
  return true;
}

bool RequestParser::check_line_limit() {
  switch (phase_) {
    case Phase::kRequestLine:
      if (line_.size() > limits_.max_target_bytes + kRequestLineSlack) {
        return fail(414,
                    "request target exceeds the limit of " + limit_text(limits_.max_target_bytes));
      }
      [[fallthrough]];
    case Phase::kHeaders:
    case Phase::kTrailers:
      if (head_bytes_ + line_.size() > limits_.max_header_bytes) {
        return fail(431, "request header section exceeds the limit of " +
                             limit_text(limits_.max_header_bytes));
      }
      return true;
    case Phase::kChunkSize:
      if (line_.size() > kMaxChunkSizeLine) {
        return fail(400, "chunk size line exceeds " + limit_text(kMaxChunkSizeLine) +
                             " (chunk extensions too long)");
      }
      return true;
    case Phase::kChunkEnd:
      // Only CRLF may follow chunk data; fail as soon as anything else shows up.
      if (line_[0] != '\r' || (line_.size() >= 2 && line_[1] != '\n')) {
        return fail(400, "chunk data is longer than its declared size (expected CRLF)");
      }
      return true;
    case Phase::kBody:
    case Phase::kChunkData:
      return true;
  }
  return true;
}

bool RequestParser::on_line(std::string_view line) {
  switch (phase_) {
    case Phase::kRequestLine:
      // RFC 9112 §2.2: blank lines before a request are tolerated; some clients send a CRLF
      // after a POST body.
      return line.empty() ? true : on_request_line(line);
    case Phase::kHeaders:
      return line.empty() ? on_headers_done() : on_field_line(line, false);
    case Phase::kChunkSize:
      return on_chunk_size_line(line);
    case Phase::kChunkEnd:
      phase_ = Phase::kChunkSize;
      return true;
    case Phase::kTrailers:
      return line.empty() ? complete() : on_field_line(line, true);
    case Phase::kBody:
    case Phase::kChunkData:
      break;
  }
  return fail(500, "request parser reached an impossible state");
}

bool RequestParser::on_request_line(std::string_view line) {
  static constexpr const char* kShape = "malformed request line; expected 'METHOD /path HTTP/1.1'";
  const std::size_t sp1 = line.find(' ');
  if (sp1 == std::string_view::npos) return fail(400, kShape);
  const std::size_t sp2 = line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos) {
    return fail(400, kShape);
  }
  const std::string_view method = line.substr(0, sp1);
  std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);

  if (!ascii::is_token(method)) return fail(400, "malformed request line: invalid method");
  if (target.empty()) return fail(400, kShape);

  const auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  if (version.size() != 8 || version.substr(0, 5) != "HTTP/" || !is_digit(version[5]) ||
      version[6] != '.' || !is_digit(version[7])) {
    return fail(400, "malformed request line: invalid HTTP version");
  }
  if (version[5] != '1' || (version[7] != '0' && version[7] != '1')) {
    return fail(
        505, "HTTP version " + std::string(version.substr(5)) + " is not supported; use HTTP/1.1");
  }

  if (target.size() > limits_.max_target_bytes) {
    return fail(414, "request target exceeds the limit of " + limit_text(limits_.max_target_bytes));
  }
  if (!std::all_of(target.begin(), target.end(), is_target_char)) {
    return fail(400,
                "request target contains a character that must be percent-encoded (space, "
                "control, non-ASCII or '#')");
  }
  // The absolute-form ("http://host:port/path?query"), which a server must accept (RFC 9112
  // §3.2.2): its authority replaces the Host field (§3.2.2 and RFC 9110 §7.2), the rest is the
  // origin-form. Authority-form (CONNECT) and asterisk-form (OPTIONS *) stay refused.
  if (target.front() != '/') {
    const std::size_t scheme_end = target.find("://");
    const std::string_view scheme =
        scheme_end == std::string_view::npos ? std::string_view() : target.substr(0, scheme_end);
    if (!ascii::iequals(scheme, "http") && !ascii::iequals(scheme, "https")) {
      return fail(400,
                  "request target must be a path starting with '/' (origin-form) or an http URI "
                  "(absolute-form)");
    }
    const std::string_view rest = target.substr(scheme_end + 3);
    const std::size_t authority_end = rest.find_first_of("/?");
    const std::string_view authority = rest.substr(0, authority_end);
    if (authority.empty() || authority.find('@') != std::string_view::npos) {
      return fail(400, "an absolute-form request target needs a host and no user information");
    }
    authority_ = std::string(authority);
    origin_form_ =
        authority_end == std::string_view::npos ? "/" : std::string(rest.substr(authority_end));
    if (origin_form_.front() == '?') origin_form_.insert(0, "/");
    target = origin_form_;
  } else {
    authority_.clear();
  }

  const std::size_t question = target.find('?');
  auto path = percent_decode(target.substr(0, question), false);
  if (!path) return fail(400, "malformed percent-encoding in request path");
  if (question != std::string_view::npos) {
    auto query = parse_query(target.substr(question + 1));
    if (!query) return fail(400, "malformed percent-encoding in query string");
    request_.query = std::move(*query);
  }

  request_.method = std::string(method);
  request_.target = std::string(target);
  request_.path = std::move(*path);
  request_.version_minor = version[7] - '0';
  phase_ = Phase::kHeaders;
  return true;
}

bool RequestParser::on_field_line(std::string_view line, bool trailer) {
  if (ascii::is_ows(line.front())) {
    return fail(400,
                "obsolete line folding (a header line starting with whitespace) is not "
                "supported");
  }
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos) return fail(400, "header line without ':'");
  const std::string_view name = line.substr(0, colon);
  if (!ascii::is_token(name)) {
    return fail(400, "invalid header name (no whitespace is allowed before ':')");
  }
  const std::string_view value = ascii::trim_ows(line.substr(colon + 1));
  if (std::any_of(value.begin(), value.end(), is_control)) {
    return fail(400, "header '" + std::string(name) + "' contains a control character");
  }
  if (++field_count_ > limits_.max_header_count) {
    return fail(431, "more than " + std::to_string(limits_.max_header_count) + " header fields");
  }
  // Trailer fields are validated (they share the header limits) but dropped: nothing here needs
  // them, and merging them into headers would let them override checked framing fields.
  if (!trailer) request_.headers.push_back({std::string(name), std::string(value)});
  return true;
}

bool RequestParser::on_headers_done() {
  headers_complete_ = true;
  std::size_t hosts = 0;
  bool has_transfer_encoding = false;
  std::string transfer_encoding;
  std::optional<std::uint64_t> content_length;
  bool expect_continue = false;

  for (const Header& h : request_.headers) {
    if (ascii::iequals(h.name, "host")) {
      ++hosts;
    } else if (ascii::iequals(h.name, "transfer-encoding")) {
      has_transfer_encoding = true;
      if (!transfer_encoding.empty()) transfer_encoding += ',';
      transfer_encoding += h.value;
    } else if (ascii::iequals(h.name, "content-length")) {
      const std::string& v = h.value;
      if (v.empty() ||
          !std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return fail(400, "invalid Content-Length; it must be a non-negative decimal integer");
      }
      std::uint64_t n = 0;
      for (char c : v) {
        const auto digit = static_cast<std::uint64_t>(c - '0');
        if (n > (std::numeric_limits<std::uint64_t>::max() - digit) / 10) {
          return fail(413,
                      "Content-Length exceeds the limit of " + limit_text(limits_.max_body_bytes));
        }
        n = n * 10 + digit;
      }
      if (content_length && *content_length != n) {
        return fail(400, "conflicting Content-Length headers");
      }
      content_length = n;
    } else if (ascii::iequals(h.name, "expect")) {
      expect_continue = ascii::iequals(h.value, "100-continue");
    }
  }

  if (!authority_.empty()) {
    // The target's authority is the host; a Host field sent along is ignored (replaced).
    std::erase_if(request_.headers, [](const Header& h) { return ascii::iequals(h.name, "host"); });
    request_.headers.push_back({"Host", authority_});
    hosts = 1;
  }
  if (hosts == 0 && request_.version_minor >= 1) {
    return fail(400, "missing Host header (required in HTTP/1.1)");
  }
  if (hosts > 1) return fail(400, "more than one Host header");

  if (has_transfer_encoding) {
    // Both present is the classic request-smuggling setup (RFC 9112 §6.3).
    if (content_length) {
      return fail(400, "Content-Length and Transfer-Encoding must not both be present");
    }
    if (request_.version_minor == 0) {
      return fail(400, "Transfer-Encoding is not allowed in HTTP/1.0 requests");
    }
    std::size_t chunked = 0;
    bool last_is_chunked = false;
    std::string unsupported;
    ascii::for_each_list_element(transfer_encoding, [&](std::string_view coding) {
      last_is_chunked = ascii::iequals(coding, "chunked");
      if (last_is_chunked) {
        ++chunked;
      } else if (unsupported.empty()) {
        unsupported = std::string(coding);
      }
    });
    if (!unsupported.empty()) {
      return fail(501, "Transfer-Encoding '" + unsupported +
                           "' is not supported; send the body with Content-Length or chunked");
    }
    if (chunked != 1 || !last_is_chunked) {
      return fail(400, "Transfer-Encoding must be exactly 'chunked'");
    }
    expect_continue_ = expect_continue && request_.version_minor >= 1;
    phase_ = Phase::kChunkSize;
    return true;
  }

  const std::uint64_t length = content_length.value_or(0);
  if (length > limits_.max_body_bytes) {
    return fail(413, "request body of " + std::to_string(length) + " bytes exceeds the limit of " +
                         limit_text(limits_.max_body_bytes));
  }
  if (length == 0) return complete();
  request_.body.reserve(std::min<std::size_t>(length, kMaxBodyReserve));
  remaining_ = length;
  expect_continue_ = expect_continue && request_.version_minor >= 1;
  phase_ = Phase::kBody;
  return true;
}

bool RequestParser::on_chunk_size_line(std::string_view line) {
  const std::size_t semicolon = line.find(';');
  std::string_view digits = line.substr(0, semicolon);
  while (!digits.empty() && ascii::is_ows(digits.back())) digits.remove_suffix(1);
  if (digits.empty()) return fail(400, "malformed chunk size line: missing chunk size");

  std::uint64_t size = 0;
  for (char c : digits) {
    const int v = hex_value(c);
    if (v < 0) return fail(400, "malformed chunk size line: chunk size must be hexadecimal");
    if (size > (std::numeric_limits<std::uint64_t>::max() >> 4)) {
      return fail(
          413, "chunked request body exceeds the limit of " + limit_text(limits_.max_body_bytes));
    }
    size = size * 16 + static_cast<std::uint64_t>(v);
  }
  if (semicolon != std::string_view::npos) {
    const std::string_view extensions = line.substr(semicolon);
    if (std::any_of(extensions.begin(), extensions.end(), is_control)) {
      return fail(400, "chunk extension contains a control character");
    }
  }

  if (size == 0) {
    phase_ = Phase::kTrailers;
    return true;
  }
  if (size > limits_.max_body_bytes - request_.body.size()) {
    return fail(413,
                "chunked request body exceeds the limit of " + limit_text(limits_.max_body_bytes));
  }
  remaining_ = size;
  phase_ = Phase::kChunkData;
  return true;
}

}  // namespace scanplan::http
