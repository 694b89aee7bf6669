// The client side of RFC 6455 that `scanplan watch` uses: its frames checked byte for byte and
// against the server's own parser, the server's frames read with that parser in client mode, the
// handshake's checks, and a live session against the real HttpServer and WebSocketHub.
#include "websocket_client.hpp"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "http/http_server.hpp"
#include "http/router.hpp"
#include "http/unique_fd.hpp"
#include "http/websocket_frame.hpp"
#include "http/websocket_handshake.hpp"
#include "http/websocket_hub.hpp"
#include "http_client_error.hpp"
#include "server/http/websocket_test_support.hpp"

using namespace std::chrono_literals;

namespace scanplan::cli {
namespace {

using http::WebSocketFrameParser;
using http::WebSocketFrameSender;
using http::WebSocketMessage;
using http::WebSocketOpcode;

// Everything a parser makes of bytes fed one at a time, the hardest split there is.
std::vector<WebSocketMessage> parse_bytewise(WebSocketFrameParser& parser, std::string_view bytes) {
  std::vector<WebSocketMessage> out;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string_view one = bytes.substr(i, 1);
    while (!one.empty() || parser.state() == WebSocketFrameParser::State::kComplete) {
      one.remove_prefix(parser.feed(one));
      if (parser.state() == WebSocketFrameParser::State::kComplete) {
        out.push_back(parser.take());
        continue;
      }
      break;
    }
    if (parser.state() == WebSocketFrameParser::State::kError) break;
  }
  return out;
}

TEST(ClientFrame, MatchesTheMaskedHelloOfRfc6455) {
  // RFC 6455 §5.7: "A single-frame masked text message".
  const std::string expected = {'\x81', '\x85', '\x37', '\xfa', '\x21', '\x3d',
                                '\x7f', '\x9f', '\x4d', '\x51', '\x58'};
  EXPECT_EQ(encode_client_frame(WebSocketOpcode::kText, "Hello", {0x37, 0xfa, 0x21, 0x3d}),
            expected);
}

TEST(ClientFrame, EveryLengthEncodingIsReadByTheServersParser) {
  for (const std::size_t n : {0u, 1u, 125u, 126u, 65535u, 65536u, 70000u}) {
    std::string payload(n, '\0');
    for (std::size_t i = 0; i < n; ++i) payload[i] = static_cast<char>('a' + i % 26);
    const std::string frame =
        encode_client_frame(WebSocketOpcode::kBinary, payload, {0x01, 0x80, 0xfe, 0x55});
    // An independent decoder: the mask bit is set, the key sits after the length.
    http::test::ServerFrame f;
    ASSERT_EQ(http::test::decode_server_frame(frame, f), frame.size()) << n;
    EXPECT_TRUE(f.masked);
    EXPECT_TRUE(f.fin);
    EXPECT_EQ(f.payload, payload);
    if (n > 0) {
      EXPECT_NE(frame.substr(frame.size() - n), payload) << "payload sent masked";
    }
    // The server's parser, which refuses unmasked client frames.
    WebSocketFrameParser parser(1 << 20);
    ASSERT_EQ(parser.feed(frame), frame.size());
    ASSERT_EQ(parser.state(), WebSocketFrameParser::State::kComplete) << n;
    const WebSocketMessage m = parser.take();
    EXPECT_EQ(m.opcode, WebSocketOpcode::kBinary);
    EXPECT_EQ(m.payload, payload);
  }
}

TEST(ClientFrame, ControlFramesReachTheServerIntact) {
  WebSocketFrameParser parser(1024);
  const std::string pong = encode_client_frame(WebSocketOpcode::kPong, "ping data", {9, 8, 7, 6});
  const std::string close_payload = http::test::close_payload(1000, "bye");
  const std::string close =
      encode_client_frame(WebSocketOpcode::kClose, close_payload, {1, 2, 3, 4});
  const auto messages = parse_bytewise(parser, pong + close);
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_EQ(messages[0].opcode, WebSocketOpcode::kPong);
  EXPECT_EQ(messages[0].payload, "ping data");
  EXPECT_EQ(messages[1].opcode, WebSocketOpcode::kClose);
  EXPECT_EQ(messages[1].close_code, 1000);
  EXPECT_EQ(messages[1].payload, "bye");
  EXPECT_THROW(encode_client_frame(WebSocketOpcode::kPing, std::string(126, 'x'), {0, 0, 0, 0}),
               std::invalid_argument);
}

TEST(ServerFrameParsing, ReadsWhatTheServerWritesAcrossAnySplit) {
  std::string big(70000, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i % 251);
  const std::string stream =
      http::encode_websocket_frame(WebSocketOpcode::kText, R"({"type":"plan_done"})") +
      http::encode_websocket_frame(WebSocketOpcode::kPing, "") +
      http::encode_websocket_frame(WebSocketOpcode::kBinary, big) +
      http::encode_websocket_close(1001, "server is shutting down");
  WebSocketFrameParser parser(1 << 20, WebSocketFrameSender::kServer);
  const auto m = parse_bytewise(parser, stream);
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[0].opcode, WebSocketOpcode::kText);
  EXPECT_EQ(m[0].payload, R"({"type":"plan_done"})");
  EXPECT_EQ(m[1].opcode, WebSocketOpcode::kPing);
  EXPECT_EQ(m[2].opcode, WebSocketOpcode::kBinary);
  EXPECT_EQ(m[2].payload, big);
  EXPECT_EQ(m[3].opcode, WebSocketOpcode::kClose);
  EXPECT_EQ(m[3].close_code, 1001);
  EXPECT_EQ(m[3].payload, "server is shutting down");
}

TEST(ServerFrameParsing, AMaskedServerFrameFailsTheConnection) {
  WebSocketFrameParser parser(1024, WebSocketFrameSender::kServer);
  parser.feed(encode_client_frame(WebSocketOpcode::kText, "hi", {1, 2, 3, 4}));
  EXPECT_EQ(parser.state(), WebSocketFrameParser::State::kError);
  EXPECT_EQ(parser.error_code(), http::websocket_close::kProtocolError);
  EXPECT_NE(parser.error_message().find("server frames must not be masked"), std::string::npos);
  // The server's side is unchanged: unmasked client frames still fail.
  WebSocketFrameParser server(1024);
  server.feed(http::encode_websocket_frame(WebSocketOpcode::kText, "hi"));
  EXPECT_EQ(server.error_code(), http::websocket_close::kProtocolError);
}

// RFC 6455 §1.3's sample key and the answer it must get.
constexpr const char* kSampleKey = "dGhlIHNhbXBsZSBub25jZQ==";

TEST(Handshake, RequestCarriesTheFieldsRfc6455Requires) {
  const std::string req =
      websocket_upgrade_request(parse_server_url("http://127.0.0.1:8080"), "/api/v1/events",
                                kSampleKey, {{"Authorization", "Bearer T"}});
  EXPECT_EQ(req.rfind("GET /api/v1/events HTTP/1.1\r\n", 0), 0u) << req;
  for (const char* field :
       {"Host: 127.0.0.1:8080\r\n", "Upgrade: websocket\r\n", "Connection: Upgrade\r\n",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n", "Sec-WebSocket-Version: 13\r\n",
        "Authorization: Bearer T\r\n"}) {
    EXPECT_NE(req.find(field), std::string::npos) << field;
  }
  EXPECT_EQ(req.substr(req.size() - 4), "\r\n\r\n");
}

TEST(Handshake, AcceptsOnlyAnAnswerThatProvesTheKeyWasRead) {
  const std::string good =
      "HTTP/1.1 101 Switching Protocols\r\nupgrade: WebSocket\r\nConnection: keep-alive, "
      "Upgrade\r\nSec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n";
  EXPECT_EQ(check_upgrade_answer(good, kSampleKey, "http://s"), 101);
  const auto refuses = [](const std::string& head, const std::string& why) {
    try {
      check_upgrade_answer(head, kSampleKey, "http://s");
      ADD_FAILURE() << "accepted: " << head;
    } catch (const HttpClientError& e) {
      EXPECT_EQ(e.kind(), HttpClientError::Kind::kNotHttp);
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  refuses(
      "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Accept: AAAAPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n",
      "does not match");
  refuses(
      "HTTP/1.1 101 Switching Protocols\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n",
      "Upgrade: websocket");
  refuses("HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n",
          "lacks Sec-WebSocket-Accept");
  refuses(good + "Sec-WebSocket-Extensions: permessage-deflate\r\n", "extension");
  refuses("SSH-2.0-OpenSSH_9.2\r\n", "not HTTP");
  EXPECT_EQ(check_upgrade_answer("HTTP/1.1 401 Unauthorized\r\nContent-Length: 5\r\n", kSampleKey,
                                 "http://s"),
            401)
      << "an HTTP error is handed back for its body to be read";
}

TEST(Handshake, KeysAreSixteenRandomBytesInBase64) {
  const std::string a = random_websocket_key(), b = random_websocket_key();
  EXPECT_EQ(a.size(), 24u);
  EXPECT_EQ(a.substr(22), "==");
  EXPECT_NE(a, b);
}

// The real server pieces: HttpServer, Router and WebSocketHub pinging every 100 ms.
class LiveWebSocket : public ::testing::Test {
 protected:
  void SetUp() override {
    http::HubConfig config;
    config.ping_interval = 100ms;
    config.pong_timeout = 300ms;
    config.log = [](std::string_view) {};
    hub_ = std::make_unique<http::WebSocketHub>(std::move(config));
    hub_->start();
    router_.add("GET", "/events", [this](const http::Request& r, const http::Router::Params&) {
      return http::websocket_handshake_response(r, hub_->adopt("test client"));
    });
    router_.add("GET", "/locked", [](const http::Request&, const http::Router::Params&) {
      return http::Response::error(401, "unauthorized", "a valid token is required");
    });
    http::ServerConfig sc;
    sc.port = 0;
    sc.log = [](std::string_view) {};
    server_ = std::make_unique<http::HttpServer>(
        sc, [this](const http::Request& r) { return router_.route(r); });
    server_->start();
    thread_ = std::thread([this] { server_->run(); });
    url_ = parse_server_url("http://127.0.0.1:" + std::to_string(server_->port()));
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
    hub_->stop();
  }

  // The next message within `limit`, calling receive() as watch does.
  std::optional<WebSocketMessage> next(WebSocketClient& c, std::chrono::milliseconds limit = 5s) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < until) {
      if (auto m = c.receive(50ms)) return m;
    }
    return std::nullopt;
  }

  bool eventually(const std::function<bool()>& cond) {
    for (int i = 0; i < 500 && !cond(); ++i) std::this_thread::sleep_for(10ms);
    return cond();
  }

  http::Router router_;
  std::unique_ptr<http::WebSocketHub> hub_;
  std::unique_ptr<http::HttpServer> server_;
  std::thread thread_;
  ServerUrl url_;
};

TEST_F(LiveWebSocket, ReceivesTextAndBinaryAndAnswersPings) {
  WebSocketClient c = WebSocketClient::connect(url_, "/events", {}, 5s);
  ASSERT_TRUE(eventually([&] { return hub_->clients() == 1; }));
  hub_->broadcast_text(R"({"type":"scan_received","scan":1})");
  auto m = next(c);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->opcode, WebSocketOpcode::kText);
  EXPECT_EQ(m->payload, R"({"type":"scan_received","scan":1})");
  hub_->broadcast_binary(1, 42, std::string(100000, 'd'));
  m = next(c);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->opcode, WebSocketOpcode::kBinary);
  EXPECT_EQ(m->payload.size(), 13u + 100000u);
  // Ten ping intervals: a client that did not answer would be dropped after 400 ms.
  const auto until = std::chrono::steady_clock::now() + 1s;
  while (std::chrono::steady_clock::now() < until) EXPECT_FALSE(c.receive(50ms));
  EXPECT_EQ(hub_->stats().clients_closed_unresponsive, 0u);
  EXPECT_EQ(hub_->clients(), 1u);
  EXPECT_LT(std::chrono::steady_clock::now() - c.last_heard(), 300ms) << "pings count as heard";
  c.close(1000, "done", 2s);
  EXPECT_FALSE(c.open());
  EXPECT_TRUE(eventually([&] { return hub_->clients() == 0; }));
}

TEST_F(LiveWebSocket, AServerShuttingDownSays1001) {
  WebSocketClient c = WebSocketClient::connect(url_, "/events", {}, 5s);
  ASSERT_TRUE(eventually([&] { return hub_->clients() == 1; }));
  std::thread stopper([this] { hub_->stop(); });
  const auto m = next(c);
  stopper.join();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->opcode, WebSocketOpcode::kClose);
  EXPECT_EQ(m->close_code, 1001);
  EXPECT_EQ(m->payload, "server is shutting down");
  EXPECT_FALSE(c.open());
  try {
    c.receive(10ms);
    FAIL() << "receive after the close";
  } catch (const HttpClientError& e) {
    EXPECT_EQ(e.kind(), HttpClientError::Kind::kNoAnswer);
  }
}

TEST_F(LiveWebSocket, ARefusalCarriesTheServersStatusAndMessage) {
  try {
    WebSocketClient::connect(url_, "/locked", {}, 5s);
    FAIL() << "connected";
  } catch (const WebSocketRefusedError& e) {
    EXPECT_EQ(e.status(), 401);
    EXPECT_NE(e.body().find("a valid token is required"), std::string::npos) << e.body();
  }
}

// A peer that completes the handshake correctly and then drops the TCP connection, as a
// crashed server does: the client must report a lost connection, not hang or crash.
TEST(WebSocketClientLoss, ADroppedConnectionIsReportedAsLost) {
  http::UniqueFd listener(::socket(AF_INET, SOCK_STREAM, 0));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener.get(), reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(listener.get(), 1), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(::getsockname(listener.get(), reinterpret_cast<sockaddr*>(&a), &len), 0);
  std::thread peer([&] {
    http::UniqueFd conn(::accept(listener.get(), nullptr, nullptr));
    std::string head;
    char buf[4096];
    while (head.find("\r\n\r\n") == std::string::npos) {
      const ssize_t n = ::recv(conn.get(), buf, sizeof buf, 0);
      if (n <= 0) return;
      head.append(buf, static_cast<std::size_t>(n));
    }
    const auto at = head.find("Sec-WebSocket-Key: ") + 19;
    const std::string key = head.substr(at, head.find("\r\n", at) - at);
    const std::string answer =
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Accept: " +
        http::websocket_accept_key(key) + "\r\n\r\n" +
        http::encode_websocket_frame(WebSocketOpcode::kText, "last words");
    ::send(conn.get(), answer.data(), answer.size(), MSG_NOSIGNAL);
  });  // conn closes here: FIN without a close frame
  WebSocketClient c = WebSocketClient::connect(
      parse_server_url("http://127.0.0.1:" + std::to_string(ntohs(a.sin_port))), "/events", {}, 5s);
  peer.join();
  auto m = c.receive(2s);
  ASSERT_TRUE(m) << "a frame sent right behind the 101 is not lost";
  EXPECT_EQ(m->payload, "last words");
  try {
    while (c.receive(2s)) {
    }
    FAIL() << "no error for a dropped connection";
  } catch (const HttpClientError& e) {
    EXPECT_EQ(e.kind(), HttpClientError::Kind::kNoAnswer);
    EXPECT_NE(std::string(e.what()).find("closed it without a WebSocket close frame"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace scanplan::cli
