#include "http/websocket_handshake.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace scanplan::http {
namespace {

// The sample key from RFC 6455 §1.3.
constexpr const char* kSampleKey = "dGhlIHNhbXBsZSBub25jZQ==";
constexpr const char* kSampleAccept = "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=";

Request upgrade_request() {
  Request r;
  r.method = "GET";
  r.target = "/api/v1/events";
  r.path = "/api/v1/events";
  r.version_minor = 1;
  r.headers = {{"Host", "127.0.0.1:8080"},
               {"Upgrade", "websocket"},
               {"Connection", "Upgrade"},
               {"Sec-WebSocket-Key", kSampleKey},
               {"Sec-WebSocket-Version", "13"}};
  return r;
}

void set(Request& r, const std::string& name, const std::string& value) {
  std::erase_if(r.headers, [&](const Header& h) { return h.name == name; });
  if (!value.empty()) r.headers.push_back({name, value});
}

UpgradeHandler noop() {
  return [](int, std::string) {};
}

int status_of(const Request& r, const WebSocketHandshakeOptions& options = {}) {
  return websocket_handshake_response(r, noop(), options).status;
}

TEST(WebSocketHandshake, AcceptKeyMatchesRfc6455) {
  EXPECT_EQ(websocket_accept_key(kSampleKey), kSampleAccept);
}

TEST(WebSocketHandshake, ValidRequestGets101) {
  bool called = false;
  const Response r =
      websocket_handshake_response(upgrade_request(), [&](int, std::string) { called = true; });
  EXPECT_EQ(r.status, 101);
  EXPECT_EQ(r.header("Upgrade"), "websocket");
  EXPECT_EQ(r.header("Connection"), "Upgrade");
  EXPECT_EQ(r.header("Sec-WebSocket-Accept"), kSampleAccept);
  EXPECT_FALSE(r.header("Sec-WebSocket-Extensions")) << "permessage-deflate is never agreed to";
  EXPECT_FALSE(r.header("Sec-WebSocket-Protocol"));
  EXPECT_TRUE(r.body.empty());
  ASSERT_TRUE(r.on_upgrade);
  r.on_upgrade(-1, "");
  EXPECT_TRUE(called);
}

TEST(WebSocketHandshake, HeaderValuesAreTokenListsAndCaseInsensitive) {
  Request r = upgrade_request();
  set(r, "Upgrade", "WebSocket");
  set(r, "Connection", "keep-alive, Upgrade");
  EXPECT_EQ(status_of(r), 101) << "Firefox sends 'keep-alive, Upgrade'";
  set(r, "Connection", "");
  r.headers.push_back({"connection", "keep-alive"});
  r.headers.push_back({"CONNECTION", "upgrade"});
  EXPECT_EQ(status_of(r), 101) << "the token may be in a repeated field";
  set(r, "Sec-WebSocket-Key", std::string(" ") + kSampleKey + " ");
  EXPECT_EQ(websocket_handshake_response(r, noop()).header("Sec-WebSocket-Accept"), kSampleAccept)
      << "surrounding whitespace is not part of the key";
  set(r, "Sec-WebSocket-Extensions", "permessage-deflate; client_max_window_bits");
  const Response with_ext = websocket_handshake_response(r, noop());
  EXPECT_EQ(with_ext.status, 101) << "offered extensions are declined by not answering them";
  EXPECT_FALSE(with_ext.header("Sec-WebSocket-Extensions"));
}

TEST(WebSocketHandshake, MissingOrWrongUpgradeIs400) {
  Request r = upgrade_request();
  set(r, "Upgrade", "");
  EXPECT_EQ(status_of(r), 400) << "a plain GET, e.g. a browser tab opened on the URL";
  set(r, "Upgrade", "h2c");
  EXPECT_EQ(status_of(r), 400);
  r = upgrade_request();
  set(r, "Connection", "keep-alive");
  EXPECT_EQ(status_of(r), 400);
  set(r, "Connection", "upgraded");
  EXPECT_EQ(status_of(r), 400) << "the token must match whole";
}

TEST(WebSocketHandshake, ErrorsAreJsonInTheRestShape) {
  Request r = upgrade_request();
  set(r, "Sec-WebSocket-Key", "");
  const Response response = websocket_handshake_response(r, noop());
  EXPECT_EQ(response.status, 400);
  EXPECT_FALSE(response.on_upgrade) << "an error must not take the socket";
  EXPECT_EQ(response.header("Content-Type"), "application/json");
  const auto body = nlohmann::json::parse(response.body);
  EXPECT_EQ(body["error"]["code"], "bad_request");
  EXPECT_NE(body["error"]["message"].get<std::string>().find("Sec-WebSocket-Key"),
            std::string::npos);
}

TEST(WebSocketHandshake, KeyMustBe16BytesOfBase64) {
  for (const std::string key : {"", "dGhlIHNhbXBsZSBub25jZQ", "dGhlIHNhbXBsZSBub25jZQ=",
                                "dGhlIHNhbXBsZSBub25jZQ===", "dGhlIHNhbXBsZSBub25j",  // 15 bytes
                                "dGhlIHNhbXBsZSBub25jZQ!=", "dGhl*HNhbXBsZSBub25jZQ==",
                                "dGhlIHNhbXBsZSBub25jZSBtb3JlIGJ5dGVz"}) {
    Request r = upgrade_request();
    set(r, "Sec-WebSocket-Key", key);
    EXPECT_EQ(status_of(r), 400) << "key '" << key << "'";
  }
  Request twice = upgrade_request();
  twice.headers.push_back({"Sec-WebSocket-Key", "AAAAAAAAAAAAAAAAAAAAAA=="});
  EXPECT_EQ(status_of(twice), 400) << "two keys";
  Request other = upgrade_request();
  set(other, "Sec-WebSocket-Key", "AAAAAAAAAAAAAAAAAAAAAA==");
  EXPECT_EQ(status_of(other), 101);
}

TEST(WebSocketHandshake, WrongVersionIs426WithTheSupportedVersion) {
  for (const std::string version : {"", "8", "12", "13, 8", "130"}) {
    Request r = upgrade_request();
    set(r, "Sec-WebSocket-Version", version);
    const Response response = websocket_handshake_response(r, noop());
    EXPECT_EQ(response.status, 426) << "version '" << version << "'";
    EXPECT_EQ(response.header("Sec-WebSocket-Version"), "13");
  }
}

TEST(WebSocketHandshake, MethodAndHttpVersion) {
  Request post = upgrade_request();
  post.method = "POST";
  const Response response = websocket_handshake_response(post, noop());
  EXPECT_EQ(response.status, 405);
  EXPECT_EQ(response.header("Allow"), "GET");
  Request head = upgrade_request();
  head.method = "HEAD";
  EXPECT_EQ(status_of(head), 405) << "HEAD reaches GET routes but cannot upgrade";
  Request old = upgrade_request();
  old.version_minor = 0;
  EXPECT_EQ(status_of(old), 400);
}

TEST(WebSocketHandshake, OriginAllowList) {
  WebSocketHandshakeOptions options;
  options.allowed_origins = {"http://127.0.0.1:8080"};
  Request r = upgrade_request();
  EXPECT_EQ(status_of(r, options), 101) << "no Origin: not a browser";
  r.headers.push_back({"Origin", "http://127.0.0.1:8080"});
  EXPECT_EQ(status_of(r, options), 101);
  set(r, "Origin", "HTTP://127.0.0.1:8080");
  EXPECT_EQ(status_of(r, options), 101);
  set(r, "Origin", "http://evil.example");
  EXPECT_EQ(status_of(r, options), 403);
  EXPECT_EQ(status_of(r), 101) << "without an allow-list any origin is accepted";
}

TEST(WebSocketHandshake, NeedsAnUpgradeHandler) {
  EXPECT_THROW(websocket_handshake_response(upgrade_request(), UpgradeHandler{}),
               std::invalid_argument);
}

TEST(WebSocketHandshake, CheckReportsWhy) {
  EXPECT_FALSE(check_websocket_handshake(upgrade_request()).has_value());
  Request r = upgrade_request();
  set(r, "Sec-WebSocket-Version", "8");
  const auto error = check_websocket_handshake(r);
  ASSERT_TRUE(error.has_value());
  EXPECT_EQ(error->status, 426);
  EXPECT_NE(error->message.find("13"), std::string::npos) << error->message;
}

}  // namespace
}  // namespace scanplan::http
