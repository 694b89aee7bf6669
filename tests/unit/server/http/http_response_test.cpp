#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "http/response.hpp"
#include "http/status.hpp"

namespace scanplan::http {
namespace {

std::string head_of(const std::string& wire) {
  return wire.substr(0, wire.find("\r\n\r\n") + 4);
}

TEST(HttpResponse, SerializesStatusHeadersAndBody) {
  Response r = Response::bytes("hello", "text/plain");
  r.status = 201;
  const std::string wire = serialize(r, true, false);
  EXPECT_EQ(wire.rfind("HTTP/1.1 201 Created\r\n", 0), 0u);
  EXPECT_NE(wire.find("\r\nContent-Type: text/plain\r\n"), std::string::npos);
  EXPECT_NE(wire.find("\r\nContent-Length: 5\r\n"), std::string::npos);
  EXPECT_NE(wire.find("\r\nDate: "), std::string::npos);
  EXPECT_EQ(wire.find("Connection:"), std::string::npos);
  EXPECT_EQ(wire.substr(wire.size() - 9), "\r\n\r\nhello");
}

TEST(HttpResponse, ConnectionCloseWhenNotKeepAlive) {
  Response r = Response::bytes("x", "text/plain");
  r.set_header("Connection", "keep-alive");
  const std::string wire = serialize(r, false, false);
  EXPECT_NE(wire.find("\r\nConnection: close\r\n"), std::string::npos);
  EXPECT_EQ(wire.find("keep-alive"), std::string::npos);
}

TEST(HttpResponse, HeadKeepsLengthButDropsBody) {
  const Response r = Response::bytes("0123456789", "application/octet-stream");
  const std::string wire = serialize(r, true, true);
  EXPECT_NE(wire.find("Content-Length: 10\r\n"), std::string::npos);
  EXPECT_EQ(wire, head_of(wire));
}

TEST(HttpResponse, BodylessStatusesHaveNoLengthOrBody) {
  Response r;
  r.status = 204;
  r.body = "ignored";
  const std::string wire = serialize(r, true, false);
  EXPECT_EQ(wire.find("Content-Length"), std::string::npos);
  EXPECT_EQ(wire, head_of(wire));
  r.status = 304;
  EXPECT_EQ(serialize(r, true, false).find("ignored"), std::string::npos);
}

TEST(HttpResponse, FramingHeadersFromHandlersAreIgnored) {
  Response r = Response::bytes("abc", "text/plain");
  r.headers.push_back({"Content-Length", "999"});
  r.headers.push_back({"Transfer-Encoding", "chunked"});
  const std::string wire = serialize(r, true, false);
  EXPECT_EQ(wire.find("999"), std::string::npos);
  EXPECT_EQ(wire.find("chunked"), std::string::npos);
  EXPECT_NE(wire.find("Content-Length: 3\r\n"), std::string::npos);
}

TEST(HttpResponse, HeaderInjectionIsNeutralised) {
  Response r;
  r.headers.push_back({"X-Echo", "a\r\nSet-Cookie: evil=1"});
  r.headers.push_back({"Bad\r\nName", "v"});
  const std::string wire = serialize(r, true, false);
  EXPECT_EQ(wire.find("\r\nSet-Cookie"), std::string::npos);
  EXPECT_NE(wire.find("X-Echo: a  Set-Cookie: evil=1\r\n"), std::string::npos);
  EXPECT_EQ(wire.find("Bad"), std::string::npos);
}

TEST(HttpResponse, ErrorHasTheRestShape) {
  const Response r = Response::error(404, "not_found", "no scan with id 7");
  EXPECT_EQ(r.status, 404);
  EXPECT_EQ(r.header("content-type"), "application/json");
  const auto j = nlohmann::json::parse(r.body);
  EXPECT_EQ(j,
            (nlohmann::json{{"error", {{"code", "not_found"}, {"message", "no scan with id 7"}}}}));
}

TEST(HttpResponse, JsonToleratesInvalidUtf8) {
  Response r;
  EXPECT_NO_THROW(r = Response::error(400, "bad_request", "bad path /\xff\xfe"));
  EXPECT_TRUE(nlohmann::json::accept(r.body));
}

TEST(HttpResponse, SetHeaderReplacesCaseInsensitively) {
  Response r;
  r.set_header("X-A", "1");
  r.set_header("x-a", "2");
  ASSERT_EQ(r.headers.size(), 1u);
  EXPECT_EQ(r.header("X-A"), "2");
}

TEST(HttpStatus, ReasonPhrasesAndCodes) {
  EXPECT_EQ(reason_phrase(200), "OK");
  EXPECT_EQ(reason_phrase(404), "Not Found");
  EXPECT_EQ(reason_phrase(431), "Request Header Fields Too Large");
  EXPECT_EQ(reason_phrase(499), "Client Error");
  EXPECT_EQ(error_code(413), "payload_too_large");
  EXPECT_EQ(error_code(500), "internal");
  EXPECT_EQ(error_code(418), "bad_request");
}

}  // namespace
}  // namespace scanplan::http
