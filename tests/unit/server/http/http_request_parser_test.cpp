#include <gtest/gtest.h>

#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "http/request_parser.hpp"

namespace scanplan::http {
namespace {

using State = RequestParser::State;

struct ParseResult {
  std::vector<Request> requests;
  int error = 0;
  std::string message;
};

// Feeds the chunks in order the way the server does: after each complete request, the rest of
// the chunk is fed again.
ParseResult parse_chunks(const std::vector<std::string_view>& chunks, const Limits& limits = {}) {
  RequestParser parser(limits);
  ParseResult result;
  for (std::string_view chunk : chunks) {
    while (true) {
      const std::size_t consumed = parser.feed(chunk);
      EXPECT_LE(consumed, chunk.size());
      chunk.remove_prefix(consumed);
      if (parser.state() == State::kComplete) {
        result.requests.push_back(parser.take());
        continue;
      }
      if (parser.state() == State::kError) {
        result.error = parser.error_status();
        result.message = parser.error_message();
        return result;
      }
      EXPECT_TRUE(chunk.empty()) << "an incomplete parser must consume all input";
      break;
    }
  }
  return result;
}

ParseResult parse(std::string_view text, const Limits& limits = {}) {
  return parse_chunks({text}, limits);
}

int error_of(std::string_view text, const Limits& limits = {}) {
  return parse(text, limits).error;
}

void expect_same(const Request& a, const Request& b) {
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.target, b.target);
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.query, b.query);
  EXPECT_EQ(a.body, b.body);
  EXPECT_EQ(a.version_minor, b.version_minor);
  ASSERT_EQ(a.headers.size(), b.headers.size());
  for (std::size_t i = 0; i < a.headers.size(); ++i) {
    EXPECT_EQ(a.headers[i].name, b.headers[i].name);
    EXPECT_EQ(a.headers[i].value, b.headers[i].value);
  }
}

const std::string kPipelined =
    "GET /api/v1/scans?since=3&name=a%20b+c HTTP/1.1\r\n"
    "Host: localhost\r\n"
    "Accept: */*\r\n"
    "\r\n"
    "POST /api/v1/scans?x=1.5&y=-2 HTTP/1.1\r\n"
    "Host: localhost\r\n"
    "Content-Length: 11\r\n"
    "\r\n"
    "hello world"
    "PUT /api/v1/params HTTP/1.1\r\n"
    "Host: localhost\r\n"
    "Transfer-Encoding: chunked\r\n"
    "\r\n"
    "5;name=value\r\n"
    "{\"a\":\r\n"
    "A\r\n"
    "0123456789\r\n"
    "0\r\n"
    "X-Trailer: yes\r\n"
    "\r\n";

TEST(HttpRequestParser, ParsesSimpleGet) {
  const auto result = parse(
      "GET /api/v1/health?verbose=1 HTTP/1.1\r\nHost: example\r\nX-Thing:  padded \t\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 1u);
  const Request& r = result.requests[0];
  EXPECT_EQ(r.method, "GET");
  EXPECT_EQ(r.target, "/api/v1/health?verbose=1");
  EXPECT_EQ(r.path, "/api/v1/health");
  EXPECT_EQ(r.query.at("verbose"), "1");
  EXPECT_EQ(r.version_minor, 1);
  EXPECT_EQ(r.header("host"), "example");
  EXPECT_EQ(r.header("HOST"), "example");
  EXPECT_EQ(r.header("x-thing"), "padded");
  EXPECT_FALSE(r.header("missing").has_value());
  EXPECT_TRUE(r.body.empty());
  EXPECT_TRUE(r.keep_alive());
}

TEST(HttpRequestParser, AbsoluteFormIsTakenWithItsAuthorityAsTheHost) {
  // RFC 9112 §3.2.2: a server must accept it; the target's authority overrides the Host field.
  const auto result = parse(
      "GET HTTP://example:8080/api/v1/scans?since=3 HTTP/1.1\r\nHost: other\r\n\r\n"
      "GET http://example HTTP/1.1\r\n\r\n"
      "GET http://example?x=1 HTTP/1.1\r\nHost: example\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 3u);
  const Request& r = result.requests[0];
  EXPECT_EQ(r.target, "/api/v1/scans?since=3");
  EXPECT_EQ(r.path, "/api/v1/scans");
  EXPECT_EQ(r.query.at("since"), "3");
  EXPECT_EQ(r.header("host"), "example:8080");
  EXPECT_EQ(result.requests[1].path, "/");
  EXPECT_EQ(result.requests[1].header("host"), "example");
  EXPECT_EQ(result.requests[2].path, "/");
  EXPECT_EQ(result.requests[2].query.at("x"), "1");
}

TEST(HttpRequestParser, DecodesPathAndQuery) {
  const auto result =
      parse("GET /a%20b/c%2Fd?x=1%2B1&name=a+b&flag&&empty=&x=second HTTP/1.1\r\nHost: h\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  const Request& r = result.requests.at(0);
  EXPECT_EQ(r.path, "/a b/c/d");
  EXPECT_EQ(r.query.at("x"), "1+1");  // first value wins
  EXPECT_EQ(r.query.at("name"), "a b");
  EXPECT_EQ(r.query.at("flag"), "");
  EXPECT_EQ(r.query.at("empty"), "");
  EXPECT_EQ(r.query.size(), 4u);
}

TEST(HttpRequestParser, KeepsDecodedDotDotAndNulForStaticServingToReject) {
  const auto result = parse("GET /%2e%2e/x%00y HTTP/1.1\r\nHost: h\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  EXPECT_EQ(result.requests.at(0).path, std::string("/../x\0y", 7));
}

TEST(HttpRequestParser, ParsesContentLengthBody) {
  const auto result = parse("POST /upload HTTP/1.1\r\nHost: h\r\nContent-Length: 5\r\n\r\nabcde");
  ASSERT_EQ(result.error, 0) << result.message;
  EXPECT_EQ(result.requests.at(0).body, "abcde");
}

TEST(HttpRequestParser, BodyIsBinarySafe) {
  std::string body;
  for (int i = 0; i < 256; ++i) body.push_back(static_cast<char>(i));
  const std::string text = "POST /u HTTP/1.1\r\nHost: h\r\nContent-Length: 256\r\n\r\n" + body;
  const auto result = parse(text);
  ASSERT_EQ(result.error, 0) << result.message;
  EXPECT_EQ(result.requests.at(0).body, body);
}

TEST(HttpRequestParser, ParsesChunkedBodyWithExtensionsAndTrailers) {
  const auto result = parse(
      "POST /u HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: Chunked\r\n\r\n"
      "4;ext=1;other=\"quoted\"\r\nWiki\r\n"
      "5 ; ext\r\npedia\r\n"
      "E\r\n in\r\n\r\nchunks.\r\n"
      "0\r\nExpires: never\r\nX-Sum: 1\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 1u);
  EXPECT_EQ(result.requests[0].body, "Wikipedia in\r\n\r\nchunks.");
  // Trailers are validated but not merged into the header fields.
  EXPECT_FALSE(result.requests[0].header("expires").has_value());
}

TEST(HttpRequestParser, ParsesPipelinedRequests) {
  const auto result = parse(kPipelined);
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 3u);
  EXPECT_EQ(result.requests[0].method, "GET");
  EXPECT_EQ(result.requests[0].query.at("name"), "a b c");
  EXPECT_EQ(result.requests[1].body, "hello world");
  EXPECT_EQ(result.requests[1].query.at("y"), "-2");
  EXPECT_EQ(result.requests[2].body, "{\"a\":0123456789");
}

TEST(HttpRequestParser, PipelinedRequestsSplitAtEveryByteBoundary) {
  const auto reference = parse(kPipelined);
  ASSERT_EQ(reference.requests.size(), 3u);
  const std::string_view all(kPipelined);
  for (std::size_t i = 0; i <= all.size(); ++i) {
    const auto result = parse_chunks({all.substr(0, i), all.substr(i)});
    ASSERT_EQ(result.error, 0) << "split at " << i << ": " << result.message;
    ASSERT_EQ(result.requests.size(), 3u) << "split at " << i;
    for (std::size_t k = 0; k < 3; ++k) expect_same(result.requests[k], reference.requests[k]);
  }
}

TEST(HttpRequestParser, PipelinedRequestsSplitAtEveryPairOfBoundaries) {
  const auto reference = parse(kPipelined);
  const std::string_view all(kPipelined);
  for (std::size_t i = 0; i <= all.size(); ++i) {
    for (std::size_t j = i; j <= all.size(); j += 3) {
      const auto result = parse_chunks({all.substr(0, i), all.substr(i, j - i), all.substr(j)});
      ASSERT_EQ(result.error, 0) << "split at " << i << "," << j;
      ASSERT_EQ(result.requests.size(), 3u) << "split at " << i << "," << j;
      for (std::size_t k = 0; k < 3; ++k) expect_same(result.requests[k], reference.requests[k]);
    }
  }
}

TEST(HttpRequestParser, OneByteAtATime) {
  const auto reference = parse(kPipelined);
  std::vector<std::string_view> bytes;
  for (std::size_t i = 0; i < kPipelined.size(); ++i) {
    bytes.push_back(std::string_view(kPipelined).substr(i, 1));
  }
  const auto result = parse_chunks(bytes);
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) expect_same(result.requests[k], reference.requests[k]);
}

TEST(HttpRequestParser, FeedStopsAtTheEndOfARequest) {
  RequestParser parser;
  const std::string_view two =
      "GET /a HTTP/1.1\r\nHost: h\r\n\r\nGET /b HTTP/1.1\r\nHost: h\r\n\r\n";
  const std::size_t first = parser.feed(two);
  EXPECT_EQ(first, two.size() / 2);
  ASSERT_EQ(parser.state(), State::kComplete);
  EXPECT_EQ(parser.feed(two.substr(first)), 0u) << "nothing is consumed until take()";
  EXPECT_EQ(parser.take().path, "/a");
  EXPECT_EQ(parser.feed(two.substr(first)), two.size() - first);
  ASSERT_EQ(parser.state(), State::kComplete);
  EXPECT_EQ(parser.take().path, "/b");
  EXPECT_EQ(parser.state(), State::kIncomplete);
}

TEST(HttpRequestParser, IgnoresBlankLinesBetweenRequests) {
  const auto result = parse(
      "POST /a HTTP/1.1\r\nHost: h\r\nContent-Length: 1\r\n\r\nx\r\n"
      "\r\nGET /b HTTP/1.1\r\nHost: h\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  ASSERT_EQ(result.requests.size(), 2u);
  EXPECT_EQ(result.requests[1].path, "/b");
}

TEST(HttpRequestParser, TracksProgressForTimeouts) {
  RequestParser parser;
  parser.feed("\r\n");
  EXPECT_FALSE(parser.started()) << "a stray CRLF between requests is not a new request";
  parser.feed("GE");
  EXPECT_TRUE(parser.started());
  EXPECT_FALSE(parser.headers_complete());
  parser.feed("T / HTTP/1.1\r\nHost: h\r\nContent-Length: 4\r\nExpect: 100-Continue\r\n\r\n");
  EXPECT_TRUE(parser.headers_complete());
  EXPECT_TRUE(parser.expects_continue());
  EXPECT_EQ(parser.state(), State::kIncomplete);
  parser.feed("body");
  ASSERT_EQ(parser.state(), State::kComplete);
  EXPECT_EQ(parser.take().body, "body");
  EXPECT_FALSE(parser.started());
  EXPECT_FALSE(parser.expects_continue());
}

TEST(HttpRequestParser, ExpectContinueIgnoredWithoutBodyOrInHttp10) {
  RequestParser parser;
  parser.feed("GET / HTTP/1.1\r\nHost: h\r\nExpect: 100-continue\r\n\r\n");
  EXPECT_EQ(parser.state(), State::kComplete);
  RequestParser old;
  old.feed("POST / HTTP/1.0\r\nContent-Length: 3\r\nExpect: 100-continue\r\n\r\n");
  EXPECT_FALSE(old.expects_continue());
}

TEST(HttpRequestParser, TakeBeforeCompleteThrows) {
  RequestParser parser;
  EXPECT_THROW(parser.take(), std::logic_error);
  parser.feed("GET / HTTP/1.1\r\n");
  EXPECT_THROW(parser.take(), std::logic_error);
}

TEST(HttpRequestParser, ResetClearsAnError) {
  RequestParser parser;
  parser.feed("BAD\r\n");
  ASSERT_EQ(parser.state(), State::kError);
  EXPECT_EQ(parser.feed("more"), 0u);
  parser.reset();
  EXPECT_EQ(parser.state(), State::kIncomplete);
  EXPECT_EQ(parser.error_status(), 0);
  parser.feed("GET / HTTP/1.1\r\nHost: h\r\n\r\n");
  EXPECT_EQ(parser.state(), State::kComplete);
}

TEST(HttpRequestParser, Http10NeedsNoHostAndClosesByDefault) {
  const auto result = parse("GET / HTTP/1.0\r\n\r\n");
  ASSERT_EQ(result.error, 0) << result.message;
  EXPECT_EQ(result.requests.at(0).version_minor, 0);
  EXPECT_FALSE(result.requests.at(0).keep_alive());
  const auto keep = parse("GET / HTTP/1.0\r\nConnection: Keep-Alive\r\n\r\n");
  EXPECT_TRUE(keep.requests.at(0).keep_alive());
}

TEST(HttpRequestParser, ConnectionCloseTokenInAnyField) {
  const auto result =
      parse("GET / HTTP/1.1\r\nHost: h\r\nConnection: foo\r\nConnection: bar, CLOSE\r\n\r\n");
  ASSERT_EQ(result.error, 0);
  EXPECT_FALSE(result.requests.at(0).keep_alive());
}

struct ErrorCase {
  const char* name;
  std::string input;
  int status;
};

void PrintTo(const ErrorCase& c, std::ostream* os) {
  *os << c.name;
}

class HttpRequestParserErrors : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(HttpRequestParserErrors, RejectsWithStatus) {
  const ErrorCase& c = GetParam();
  const auto whole = parse(c.input);
  EXPECT_EQ(whole.error, c.status) << whole.message;
  EXPECT_TRUE(whole.requests.empty());
  EXPECT_FALSE(whole.message.empty());

  std::vector<std::string_view> bytes;
  for (std::size_t i = 0; i < c.input.size(); ++i) {
    bytes.push_back(std::string_view(c.input).substr(i, 1));
  }
  EXPECT_EQ(parse_chunks(bytes).error, c.status) << "fed one byte at a time";
}

const std::string kHost = "Host: h\r\n";

// A string from a literal that may contain NUL bytes.
template <std::size_t N>
std::string bytes(const char (&literal)[N]) {
  return std::string(literal, N - 1);
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, HttpRequestParserErrors,
    ::testing::Values(
        ErrorCase{"no_target", "GET\r\n\r\n", 400},
        ErrorCase{"double_space", "GET  / HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"extra_token", "GET / HTTP/1.1 x\r\n" + kHost + "\r\n", 400},
        ErrorCase{"missing_version", "GET /\r\n" + kHost + "\r\n", 400},
        ErrorCase{"bad_method", "G(T / HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"lowercase_version", "GET / http/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"version_garbage", "GET / HTTP/1.x\r\n" + kHost + "\r\n", 400},
        ErrorCase{"http2", "GET / HTTP/2.0\r\n" + kHost + "\r\n", 505},
        ErrorCase{"http12", "GET / HTTP/1.2\r\n" + kHost + "\r\n", 505},
        ErrorCase{"absolute_form_userinfo", "GET http://u@h/ HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"absolute_form_no_host", "GET http:///a HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"other_scheme", "GET ftp://h/a HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"authority_form", "CONNECT h:443 HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"asterisk_form", "OPTIONS * HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"control_in_target", "GET /a\x01 HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"non_ascii_target", "GET /caf\xc3\xa9 HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"fragment", "GET /a#b HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"bad_escape", "GET /%zz HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"truncated_escape", "GET /a% HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"bad_query_escape", "GET /a?x=%4 HTTP/1.1\r\n" + kHost + "\r\n", 400},
        ErrorCase{"bare_lf_request_line", "GET / HTTP/1.1\n" + kHost + "\r\n", 400},
        ErrorCase{"bare_lf_header", "GET / HTTP/1.1\r\nHost: h\n\r\n", 400},
        ErrorCase{"bare_cr_in_header", "GET / HTTP/1.1\r\nHost: h\rX: y\r\n\r\n", 400},
        ErrorCase{"obs_fold", "GET / HTTP/1.1\r\n" + kHost + "X: a\r\n  b\r\n\r\n", 400},
        ErrorCase{"space_before_colon", "GET / HTTP/1.1\r\nHost : h\r\n\r\n", 400},
        ErrorCase{"space_in_name", "GET / HTTP/1.1\r\n" + kHost + "Bad Name: x\r\n\r\n", 400},
        ErrorCase{"no_colon", "GET / HTTP/1.1\r\n" + kHost + "NoColon\r\n\r\n", 400},
        ErrorCase{"empty_name", "GET / HTTP/1.1\r\n" + kHost + ": x\r\n\r\n", 400},
        ErrorCase{"nul_in_value", bytes("GET / HTTP/1.1\r\nHost: h\0x\r\n\r\n"), 400},
        ErrorCase{"missing_host", "GET / HTTP/1.1\r\nAccept: */*\r\n\r\n", 400},
        ErrorCase{"two_hosts", "GET / HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n", 400},
        ErrorCase{"cl_letters", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: abc\r\n\r\n", 400},
        ErrorCase{"cl_negative", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: -1\r\n\r\n", 400},
        ErrorCase{"cl_plus", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: +1\r\n\r\n", 400},
        ErrorCase{"cl_empty", "POST / HTTP/1.1\r\n" + kHost + "Content-Length:\r\n\r\n", 400},
        ErrorCase{"cl_list", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: 1, 1\r\n\r\nx", 400},
        ErrorCase{"cl_hex", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: 0x10\r\n\r\n", 400},
        ErrorCase{"cl_space_inside", "POST / HTTP/1.1\r\n" + kHost + "Content-Length: 1 0\r\n\r\n",
                  400},
        ErrorCase{
            "cl_conflict",
            "POST / HTTP/1.1\r\n" + kHost + "Content-Length: 1\r\nContent-Length: 2\r\n\r\nxx",
            400},
        ErrorCase{
            "cl_overflow",
            "POST / HTTP/1.1\r\n" + kHost + "Content-Length: 99999999999999999999999999\r\n\r\n",
            413},
        ErrorCase{"cl_and_te",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Content-Length: 3\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n",
                  400},
        ErrorCase{"te_and_cl",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\nContent-Length: 3\r\n\r\n0\r\n\r\n",
                  400},
        ErrorCase{"te_gzip", "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: gzip\r\n\r\n",
                  501},
        ErrorCase{"te_gzip_chunked",
                  "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: gzip, chunked\r\n\r\n", 501},
        ErrorCase{"te_chunked_twice",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\nTransfer-Encoding: chunked\r\n\r\n",
                  400},
        ErrorCase{"te_empty", "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: \r\n\r\n", 400},
        ErrorCase{"te_in_http10", "POST / HTTP/1.0\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n",
                  400},
        ErrorCase{"chunk_size_not_hex",
                  "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\nzz\r\n", 400},
        ErrorCase{"chunk_size_empty",
                  "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\n;x\r\n", 400},
        ErrorCase{"chunk_size_negative",
                  "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\n-1\r\n", 400},
        ErrorCase{"chunk_size_leading_space",
                  "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\n 1\r\n", 400},
        ErrorCase{"chunk_data_too_long",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\n\r\n2\r\nabc\r\n0\r\n\r\n",
                  400},
        ErrorCase{
            "chunk_bare_lf",
            "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\n2\nab\r\n0\r\n\r\n",
            400},
        ErrorCase{"chunk_size_overflow",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\n\r\nFFFFFFFFFFFFFFFFFF\r\n",
                  413},
        ErrorCase{"chunk_ext_control",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\n\r\n1;a\x01\r\nx\r\n0\r\n\r\n",
                  400},
        ErrorCase{"trailer_bad_name",
                  "POST / HTTP/1.1\r\n" + kHost +
                      "Transfer-Encoding: chunked\r\n\r\n0\r\nBad Trailer: x\r\n\r\n",
                  400}),
    [](const ::testing::TestParamInfo<ErrorCase>& param_info) {
      return std::string(param_info.param.name);
    });

TEST(HttpRequestParser, AcceptsIdenticalDuplicateContentLength) {
  const auto result = parse(
      "POST / HTTP/1.1\r\nHost: h\r\nContent-Length: 2\r\n"
      "Content-Length: 02\r\n\r\nok");
  ASSERT_EQ(result.error, 0) << result.message;
  EXPECT_EQ(result.requests.at(0).body, "ok");
}

TEST(HttpRequestParser, OversizedHeaderSectionIs431) {
  Limits limits;
  limits.max_header_bytes = 1024;
  const std::string big(2000, 'a');
  EXPECT_EQ(error_of("GET / HTTP/1.1\r\nHost: h\r\nX-Big: " + big + "\r\n\r\n", limits), 431);
  std::string many = "GET / HTTP/1.1\r\nHost: h\r\n";
  for (int i = 0; i < 100; ++i) many += "X-" + std::to_string(i) + ": 0123456789\r\n";
  EXPECT_EQ(error_of(many + "\r\n", limits), 431);
  // The limit triggers while the header is still arriving, without waiting for its end.
  RequestParser parser(limits);
  parser.feed("GET / HTTP/1.1\r\nHost: h\r\nX-Big: " + big);
  EXPECT_EQ(parser.state(), State::kError);
  EXPECT_EQ(parser.error_status(), 431);
}

TEST(HttpRequestParser, TooManyHeaderFieldsIs431) {
  Limits limits;
  limits.max_header_count = 5;
  std::string text = "GET / HTTP/1.1\r\nHost: h\r\n";
  for (int i = 0; i < 5; ++i) text += "X-" + std::to_string(i) + ": v\r\n";
  EXPECT_EQ(error_of(text + "\r\n", limits), 431);
}

TEST(HttpRequestParser, LongTargetIs414) {
  Limits limits;
  limits.max_target_bytes = 100;
  const std::string path = "/" + std::string(150, 'p');
  EXPECT_EQ(error_of("GET " + path + " HTTP/1.1\r\nHost: h\r\n\r\n", limits), 414);
  // Detected before the end of the line arrives.
  RequestParser parser(limits);
  parser.feed("GET /" + std::string(1000, 'p'));
  EXPECT_EQ(parser.error_status(), 414);
}

TEST(HttpRequestParser, OversizedBodiesAre413) {
  Limits limits;
  limits.max_body_bytes = 10;
  EXPECT_EQ(error_of("POST / HTTP/1.1\r\nHost: h\r\nContent-Length: 11\r\n\r\n", limits), 413);
  EXPECT_EQ(error_of("POST / HTTP/1.1\r\nHost: h\r\nContent-Length: 10\r\n\r\n0123456789", limits),
            0);
  EXPECT_EQ(error_of("POST / HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\n\r\n"
                     "6\r\n012345\r\n5\r\n",
                     limits),
            413);
  EXPECT_EQ(error_of("POST / HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\n\r\n"
                     "5\r\n01234\r\n5\r\n56789\r\n0\r\n\r\n",
                     limits),
            0);
}

TEST(HttpRequestParser, ErrorMessagesAreActionable) {
  const auto both = parse(
      "POST / HTTP/1.1\r\nHost: h\r\nContent-Length: 1\r\nTransfer-Encoding: chunked\r\n\r\n");
  EXPECT_NE(both.message.find("Content-Length"), std::string::npos);
  EXPECT_NE(both.message.find("Transfer-Encoding"), std::string::npos);
  const auto host = parse("GET / HTTP/1.1\r\n\r\n");
  EXPECT_NE(host.message.find("Host"), std::string::npos);
  Limits limits;
  limits.max_body_bytes = 10;
  const auto big = parse("POST / HTTP/1.1\r\nHost: h\r\nContent-Length: 99\r\n\r\n", limits);
  EXPECT_NE(big.message.find("10 bytes"), std::string::npos) << big.message;
}

// Random mutations of valid requests, fed in random pieces: the parser must never crash, never
// consume more than it was given, and always consume everything while incomplete.
TEST(HttpRequestParser, SurvivesRandomMutations) {
  std::mt19937 rng(12345);
  static constexpr char kAlphabet[] = "\r\n :;%0aZ\t\0\xff-,/?=&";
  const std::string alphabet(kAlphabet, sizeof(kAlphabet) - 1);
  Limits limits;
  limits.max_body_bytes = 1 << 16;
  for (int iteration = 0; iteration < 20000; ++iteration) {
    std::string text = kPipelined;
    const int mutations = 1 + static_cast<int>(rng() % 4);
    for (int m = 0; m < mutations; ++m) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[at] = alphabet[rng() % alphabet.size()];
          break;
        case 1:
          text.insert(at, 1, alphabet[rng() % alphabet.size()]);
          break;
        default:
          text.erase(at, 1 + rng() % 8);
          break;
      }
      if (text.empty()) text = "x";
    }
    RequestParser parser(limits);
    std::string_view rest(text);
    while (!rest.empty() && parser.state() != State::kError) {
      const std::size_t piece = 1 + rng() % 64;
      std::string_view chunk = rest.substr(0, piece);
      rest.remove_prefix(chunk.size());
      while (true) {
        const std::size_t n = parser.feed(chunk);
        ASSERT_LE(n, chunk.size());
        chunk.remove_prefix(n);
        if (parser.state() == State::kComplete) {
          parser.take();
          continue;
        }
        if (parser.state() == State::kIncomplete) {
          ASSERT_TRUE(chunk.empty());
        }
        break;
      }
    }
    if (parser.state() == State::kError) {
      const int s = parser.error_status();
      EXPECT_TRUE(s == 400 || s == 413 || s == 414 || s == 431 || s == 501 || s == 505) << s;
    }
  }
}

}  // namespace
}  // namespace scanplan::http
