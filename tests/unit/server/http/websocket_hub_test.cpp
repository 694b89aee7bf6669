#include "http/websocket_hub.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "http/http_server.hpp"
#include "http/router.hpp"
#include "http/websocket_frame.hpp"
#include "http/websocket_handshake.hpp"
#include "websocket_test_support.hpp"

using namespace std::chrono_literals;

namespace scanplan::http {
namespace {

using test::client_frame;
using test::close_payload;
using test::ServerFrame;

constexpr std::uint8_t kText = 0x1;
constexpr std::uint8_t kBinary = 0x2;
constexpr std::uint8_t kClose = 0x8;
constexpr std::uint8_t kPing = 0x9;
constexpr std::uint8_t kPong = 0xA;

// Polls cond until it holds or the time is up; for state that another thread changes.
bool eventually(const std::function<bool()>& cond, std::chrono::milliseconds limit = 5s) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!cond()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

std::uint64_t read_le(std::string_view bytes, std::size_t at, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | static_cast<std::uint8_t>(bytes[at + i]);
  return v;
}

// A WebSocket client on a raw blocking socket, so every byte on the wire is under the test's
// control (masking, fragmentation, not reading at all).
class WsClient {
 public:
  // receive_buffer > 0 fixes SO_RCVBUF before connecting, which keeps the kernel from absorbing
  // megabytes on behalf of a client that does not read.
  explicit WsClient(std::uint16_t port, int receive_buffer = 0)
      : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    if (receive_buffer > 0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
  }
  ~WsClient() { close(); }
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

  // Sends the opening handshake (plus any bytes to send in the same write) and reads the
  // response head. The status, or 0 when none arrived.
  int handshake(const std::string& early = "") {
    if (!connected_) return 0;
    const std::string request =
        "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
    if (!send_raw(request + early)) return 0;
    return read_head();
  }

  // Reads one HTTP response head; its status, or 0 when none arrived.
  int read_head() {
    std::size_t end;
    while ((end = buffer_.find("\r\n\r\n")) == std::string::npos) {
      if (!fill(5s)) return 0;
    }
    head_ = buffer_.substr(0, end);
    buffer_.erase(0, end + 4);
    if (head_.rfind("HTTP/1.1 ", 0) != 0) return 0;
    return std::stoi(head_.substr(9, 3));
  }
  const std::string& head() const { return head_; }

  bool send_raw(std::string_view data) {
    while (!data.empty()) {
      const ssize_t n = ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL);
      if (n <= 0) return false;
      data.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
  }

  bool send_frame(std::uint8_t opcode, std::string_view payload) {
    return send_raw(client_frame(opcode, payload));
  }

  // The next frame, or nullopt on end of stream (see eof()) or timeout.
  std::optional<ServerFrame> read_frame(std::chrono::milliseconds timeout = 5s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (true) {
      ServerFrame f;
      if (const std::size_t used = test::decode_server_frame(buffer_, f); used > 0) {
        buffer_.erase(0, used);
        return f;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          until - std::chrono::steady_clock::now());
      if (left <= 0ms || !fill(left)) return std::nullopt;
    }
  }

  // The next frame that is not a ping (pings are answered), for tests about other traffic.
  std::optional<ServerFrame> read_data_frame(std::chrono::milliseconds timeout = 5s) {
    while (auto f = read_frame(timeout)) {
      if (f->opcode != kPing) return f;
      send_frame(kPong, f->payload);
    }
    return std::nullopt;
  }

  // True once the server has closed the connection and every byte before that was read.
  bool eof() const { return eof_; }

  // Reads and discards until the server closes the connection. False on timeout.
  bool wait_for_eof(std::chrono::milliseconds timeout = 5s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!eof_) {
      buffer_.clear();
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          until - std::chrono::steady_clock::now());
      if (left <= 0ms) return false;
      fill(left);
    }
    return true;
  }

  // Closes with RST instead of FIN, like a browser tab that crashed.
  void abort() {
    linger l{1, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof(l));
    close();
  }

  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  bool fill(std::chrono::milliseconds timeout) {
    if (eof_ || fd_ < 0) return false;
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return false;
    char chunk[65536];
    const ssize_t n = ::recv(fd_, chunk, sizeof(chunk), 0);
    if (n <= 0) {
      eof_ = true;  // FIN, or RST after the server closed with data unread
      return false;
    }
    buffer_.append(chunk, static_cast<std::size_t>(n));
    return true;
  }

  int fd_;
  bool connected_ = false;
  bool eof_ = false;
  std::string buffer_;
  std::string head_;
};

// An HttpServer on an ephemeral loopback port whose route /ws upgrades into a hub, as the API
// will do for /api/v1/events.
class WebSocketHubTest : public ::testing::Test {
 protected:
  void start(HubConfig config = {}) {
    if (!config.log) {
      config.log = [this](std::string_view m) {
        const std::lock_guard lock(log_mutex_);
        log_ += std::string(m) + "\n";
      };
    }
    hub_ = std::make_unique<WebSocketHub>(std::move(config));
    hub_->start();
    router_.add("GET", "/ws", [this](const Request& r, const Router::Params&) {
      return websocket_handshake_response(r, hub_->adopt(r.peer + " (test)"));
    });
    ServerConfig server_config;
    server_config.port = 0;
    server_config.log = [this](std::string_view m) {
      const std::lock_guard lock(log_mutex_);
      log_ += std::string(m) + "\n";
    };
    server_ = std::make_unique<HttpServer>(std::move(server_config),
                                           [this](const Request& r) { return router_.route(r); });
    server_->start();
    server_thread_ = std::thread([this] { server_->run(); });
  }

  void TearDown() override {
    if (server_) {
      server_->stop();
      server_thread_.join();
    }
    if (hub_) hub_->stop();
  }

  // A client past its handshake, once the hub has adopted it.
  std::unique_ptr<WsClient> connect(int receive_buffer = 0) {
    const std::size_t before = hub_->clients();
    auto c = std::make_unique<WsClient>(server_->port(), receive_buffer);
    EXPECT_EQ(c->handshake(), 101) << c->head();
    EXPECT_TRUE(eventually([&] { return hub_->clients() > before; })) << "hub did not adopt";
    return c;
  }

  std::string log() {
    const std::lock_guard lock(log_mutex_);
    return log_;
  }

  WebSocketHub& hub() { return *hub_; }

  Router router_;
  std::unique_ptr<WebSocketHub> hub_;
  std::unique_ptr<HttpServer> server_;
  std::thread server_thread_;
  std::mutex log_mutex_;
  std::string log_;
};

TEST_F(WebSocketHubTest, HandshakeOverARealServer) {
  start();
  WsClient c(server_->port());
  ASSERT_EQ(c.handshake(), 101);
  EXPECT_NE(c.head().find("Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo="), std::string::npos)
      << c.head();
  EXPECT_TRUE(eventually([&] { return hub().clients() == 1; }));

  WsClient plain(server_->port());
  ASSERT_TRUE(plain.send_raw("GET /ws HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_EQ(plain.read_head(), 400);
  EXPECT_EQ(hub().clients(), 1u) << "a plain GET is never adopted";
}

TEST_F(WebSocketHubTest, EveryClientGetsEveryTextEvent) {
  start();
  auto a = connect();
  auto b = connect();
  hub().broadcast_text(R"({"type":"scan_received","id":1})");
  hub().broadcast_text(R"({"type":"match_done","id":1})");
  for (WsClient* c : {a.get(), b.get()}) {
    auto f1 = c->read_data_frame();
    auto f2 = c->read_data_frame();
    ASSERT_TRUE(f1 && f2);
    EXPECT_TRUE(f1->fin);
    EXPECT_FALSE(f1->masked) << "servers never mask";
    EXPECT_EQ(f1->opcode, kText);
    EXPECT_EQ(f1->payload, R"({"type":"scan_received","id":1})");
    EXPECT_EQ(f2->payload, R"({"type":"match_done","id":1})");
  }
}

TEST_F(WebSocketHubTest, BinaryChunksCarryOpIdAndSendTime) {
  start();
  auto c = connect();
  const auto ns_now = [] {
    return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                          std::chrono::system_clock::now().time_since_epoch())
                                          .count());
  };
  const std::uint64_t before = ns_now();
  std::string payload(70000, '\0');
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<char>(i % 251);
  hub().broadcast_binary(3, 0xA1B2C3D4, payload);
  const std::uint64_t after = ns_now();

  const auto f = c->read_data_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kBinary);
  ASSERT_EQ(f->payload.size(), 13 + payload.size());
  EXPECT_EQ(static_cast<std::uint8_t>(f->payload[0]), 3);
  EXPECT_EQ(read_le(f->payload, 1, 4), 0xA1B2C3D4u) << "little-endian id";
  const std::uint64_t ns = read_le(f->payload, 5, 8);
  EXPECT_GE(ns, before);
  EXPECT_LE(ns, after);
  EXPECT_EQ(f->payload.substr(13), payload);
}

TEST_F(WebSocketHubTest, AnswersClientPingsWithTheirPayload) {
  start();
  auto c = connect();
  ASSERT_TRUE(c->send_frame(kPing, "are you there"));
  const auto f = c->read_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kPong);
  EXPECT_EQ(f->payload, "are you there");
}

TEST_F(WebSocketHubTest, BytesSentWithTheHandshakeAreNotLost) {
  start();
  WsClient c(server_->port());
  ASSERT_EQ(c.handshake(client_frame(kPing, "early")), 101);
  const auto f = c.read_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kPong);
  EXPECT_EQ(f->payload, "early");
}

TEST_F(WebSocketHubTest, PingsClientsAndDropsThoseThatDoNotAnswer) {
  HubConfig config;
  config.ping_interval = 100ms;
  config.pong_timeout = 300ms;
  start(config);
  auto answering = connect();
  auto silent = connect();

  // The answering client keeps pace for several ping rounds; the silent one reads but never
  // answers.
  std::atomic<bool> silent_saw_ping{false};
  std::thread silent_reader([&] {
    while (auto f = silent->read_frame(3s)) {
      if (f->opcode == kPing) silent_saw_ping = true;
    }
  });
  int pings = 0;
  const auto until = std::chrono::steady_clock::now() + 900ms;
  while (std::chrono::steady_clock::now() < until) {
    const auto f = answering->read_frame(300ms);
    if (!f) continue;
    ASSERT_EQ(f->opcode, kPing);
    ++pings;
    ASSERT_TRUE(answering->send_frame(kPong, f->payload));
  }
  silent_reader.join();
  EXPECT_GE(pings, 3);
  EXPECT_TRUE(silent_saw_ping);
  EXPECT_TRUE(silent->eof()) << "the silent client was disconnected";
  EXPECT_EQ(hub().clients(), 1u);
  EXPECT_EQ(hub().stats().clients_closed_unresponsive, 1u);
  EXPECT_NE(log().find("did not answer a ping"), std::string::npos) << log();
}

TEST_F(WebSocketHubTest, ClientInitiatedCloseIsEchoedThenTheServerCloses) {
  start();
  auto c = connect();
  ASSERT_TRUE(c->send_frame(kClose, close_payload(1000, "tab closed")));
  const auto f = c->read_data_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kClose);
  EXPECT_EQ(f->close_code(), 1000);
  EXPECT_TRUE(c->wait_for_eof()) << "the server closes TCP after the close handshake";
  EXPECT_TRUE(eventually([&] { return hub().clients() == 0; }));
}

TEST_F(WebSocketHubTest, CloseWithoutCodeIsAnsweredWithoutCode) {
  start();
  auto c = connect();
  ASSERT_TRUE(c->send_frame(kClose, ""));
  const auto f = c->read_data_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kClose);
  EXPECT_TRUE(f->payload.empty());
  EXPECT_TRUE(c->wait_for_eof());
}

// Sends bytes and expects the hub to fail the connection with code.
void expect_failed_with(WsClient& c, std::string_view bytes, std::uint16_t code) {
  ASSERT_TRUE(c.send_raw(bytes));
  const auto f = c.read_data_frame();
  ASSERT_TRUE(f) << "expected a close frame with " << code;
  EXPECT_EQ(f->opcode, kClose);
  EXPECT_EQ(f->close_code(), code) << f->close_reason();
  EXPECT_TRUE(c.wait_for_eof());
}

TEST_F(WebSocketHubTest, ProtocolErrorsCloseWithTheRightCode) {
  HubConfig config;
  config.max_message_bytes = 1024;
  start(config);
  auto unmasked = connect();
  expect_failed_with(*unmasked, client_frame(kText, "hi", true, false),
                     websocket_close::kProtocolError);
  auto binary = connect();
  expect_failed_with(*binary, client_frame(kBinary, "\x01\x02"), websocket_close::kUnsupportedData);
  auto big = connect();
  expect_failed_with(*big, client_frame(kText, std::string(2000, 'x')),
                     websocket_close::kMessageTooBig);
  auto bad_text = connect();
  expect_failed_with(*bad_text, client_frame(kText, "\xC0\xAF"), websocket_close::kInvalidPayload);
  auto garbage = connect();
  expect_failed_with(*garbage, "GET / HTTP/1.1\r\n\r\n", websocket_close::kProtocolError);
  EXPECT_TRUE(eventually([&] { return hub().clients() == 0; }));
  EXPECT_NE(log().find("(test)"), std::string::npos) << "logs name the client:\n" << log();
}

TEST_F(WebSocketHubTest, CloseFrameSurvivesInputStillInFlight) {
  HubConfig config;
  config.max_message_bytes = 1024;
  start(config);
  auto c = connect();
  // Refused from its header while half a megabyte of its payload is still arriving: closing the
  // socket with that input unread would reset the connection and could destroy the close frame.
  const std::string frame = client_frame(kBinary, std::string(512 * 1024, 'z'));
  std::thread sender([&] { c->send_raw(frame); });
  const auto f = c->read_data_frame();
  sender.join();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kClose);
  EXPECT_EQ(f->close_code(), websocket_close::kMessageTooBig);
  EXPECT_TRUE(c->wait_for_eof());
  c->close();
  EXPECT_TRUE(eventually([&] { return hub().clients() == 0; }));
}

TEST_F(WebSocketHubTest, ClientMessagesReachOnMessageWhichCanAnswer) {
  HubConfig config;
  std::mutex m;
  std::vector<std::string> received;
  config.on_message = [&](std::uint64_t client, std::string_view label, std::string text) {
    {
      const std::lock_guard lock(m);
      received.push_back(std::string(label) + "|" + text);
    }
    hub_->send_text(client, R"({"type":"pong"})");
  };
  start(config);
  auto c = connect();
  auto other = connect();
  ASSERT_TRUE(
      c->send_raw(client_frame(kText, R"({"type":)", false) + client_frame(0x0, R"("ping"})")));
  const auto f = c->read_data_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->payload, R"({"type":"pong"})");
  {
    const std::lock_guard lock(m);
    ASSERT_EQ(received.size(), 1u);
    EXPECT_NE(received[0].find(R"((test)|{"type":"ping"})"), std::string::npos) << received[0];
  }
  EXPECT_FALSE(other->read_data_frame(200ms)) << "the answer went to the asking client only";
  EXPECT_FALSE(hub().send_text(987654, "{}")) << "unknown client";
}

TEST_F(WebSocketHubTest, SlowClientLosesStaleChunksButNotEvents) {
  HubConfig config;
  config.max_queued_text_bytes = 256 * 1024;
  config.max_queued_binary_bytes = 1 << 20;
  config.send_buffer_bytes = 64 * 1024;
  start(config);
  auto slow = connect(32 * 1024);
  const std::size_t bound = hub().max_queued_bytes_per_client();

  // The client reads nothing while ~30 MB of map chunks and a few events go out.
  constexpr int kChunks = 150;
  constexpr int kEventEvery = 10;
  const std::string chunk(200 * 1024, 'm');
  int events = 0;
  for (int i = 0; i < kChunks; ++i) {
    hub().broadcast_binary(1, static_cast<std::uint32_t>(i), chunk);
    if (i % kEventEvery == 0) {
      hub().broadcast_text(nlohmann::json{{"type", "scan_progress"}, {"seq", events++}}.dump());
    }
    ASSERT_LE(hub().stats().queued_bytes, bound) << "after chunk " << i;
  }
  const HubStats during = hub().stats();
  EXPECT_LE(during.peak_client_queued_bytes, bound);
  EXPECT_GT(during.binary_frames_dropped, 0u);
  EXPECT_EQ(during.clients_closed_slow, 0u);

  // Reading again, the client gets every event in order, the newest chunks in order, and the
  // notice that chunks were dropped.
  hub().broadcast_text(R"({"type":"after_resume"})");
  int next_event = 0;
  bool resumed_event = false;
  std::uint64_t notified_drops = 0;
  std::int64_t last_chunk = -1;
  int chunks_received = 0;
  while (!resumed_event || chunks_received + static_cast<int>(notified_drops) < kChunks) {
    const auto f = slow->read_data_frame();
    ASSERT_TRUE(f) << "stream ended: events " << next_event << ", chunks " << chunks_received
                   << ", drops notified " << notified_drops;
    if (f->opcode == kBinary) {
      const auto id = static_cast<std::int64_t>(read_le(f->payload, 1, 4));
      EXPECT_GT(id, last_chunk) << "chunks stay in order";
      last_chunk = id;
      ++chunks_received;
      continue;
    }
    ASSERT_EQ(f->opcode, kText);
    const auto j = nlohmann::json::parse(f->payload);
    if (j["type"] == "scan_progress") {
      EXPECT_EQ(j["seq"], next_event++) << "events are never dropped or reordered";
    } else if (j["type"] == "binary_dropped") {
      EXPECT_GT(j["count"].get<std::uint64_t>(), 0u);
      EXPECT_LE(j["first_id"].get<std::uint32_t>(), j["last_id"].get<std::uint32_t>());
      notified_drops += j["count"].get<std::uint64_t>();
    } else {
      EXPECT_EQ(j["type"], "after_resume");
      resumed_event = true;
    }
  }
  EXPECT_EQ(next_event, events);
  EXPECT_LT(chunks_received, kChunks);
  EXPECT_EQ(notified_drops, hub().stats().binary_frames_dropped);
  EXPECT_EQ(last_chunk, kChunks - 1) << "the newest chunk is kept";
  EXPECT_EQ(hub().clients(), 1u);
}

TEST_F(WebSocketHubTest, ClientTooSlowForEventsIsClosedWith1013) {
  HubConfig config;
  config.max_queued_text_bytes = 64 * 1024;
  config.send_buffer_bytes = 32 * 1024;
  config.close_timeout = 300ms;
  start(config);
  auto slow = connect(16 * 1024);
  auto fast = connect();
  std::atomic<int> fast_events{0};
  std::thread fast_reader([&] {
    while (auto f = fast->read_data_frame(5s)) {
      if (f->opcode != kText) continue;
      ++fast_events;
      if (f->payload.find("still_here") != std::string::npos) break;
    }
  });

  // Paced so the fast client is never behind by more than a batch.
  const std::string event = R"({"type":"scan_progress","pad":")" + std::string(1000, 'p') + "\"}";
  int sent = 0;
  for (int batch = 0; batch < 100 && hub().stats().clients_closed_slow == 0; ++batch) {
    for (int i = 0; i < 20; ++i, ++sent) hub().broadcast_text(event);
    ASSERT_TRUE(eventually([&] { return fast_events.load() == sent; }));
    ASSERT_LE(hub().stats().peak_client_queued_bytes, hub().max_queued_bytes_per_client());
  }
  EXPECT_EQ(hub().stats().clients_closed_slow, 1u);
  EXPECT_TRUE(eventually([&] { return hub().clients() == 1; })) << "the fast client stays";
  EXPECT_NE(log().find("closing it with 1013"), std::string::npos) << log();

  // The slow client gets what fit in the socket buffers, then the end of the stream.
  EXPECT_TRUE(slow->wait_for_eof());
  hub().broadcast_text(R"({"type":"still_here"})");
  fast_reader.join();
  EXPECT_EQ(fast_events.load(), sent + 1) << "the fast client got every event";
}

TEST_F(WebSocketHubTest, VanishedClientDoesNotRaiseSigpipe) {
  start();
  auto c = connect();
  c->abort();
  // Writing to a reset connection raises SIGPIPE unless the hub uses MSG_NOSIGNAL; the default
  // action would kill this test process.
  const std::string chunk(64 * 1024, 'x');
  for (int i = 0; i < 100; ++i) hub().broadcast_binary(1, static_cast<std::uint32_t>(i), chunk);
  EXPECT_TRUE(eventually([&] { return hub().clients() == 0; }));
}

TEST_F(WebSocketHubTest, StopClosesEveryClientWith1001) {
  HubConfig config;
  config.close_timeout = 500ms;
  start(config);
  auto polite = connect();
  auto mute = connect();  // never answers the close
  std::thread stopper([&] { hub().stop(); });

  const auto f = polite->read_data_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->opcode, kClose);
  EXPECT_EQ(f->close_code(), websocket_close::kGoingAway);
  ASSERT_TRUE(polite->send_frame(kClose, close_payload(websocket_close::kGoingAway)));
  EXPECT_TRUE(polite->wait_for_eof());

  const auto g = mute->read_data_frame();
  ASSERT_TRUE(g);
  EXPECT_EQ(g->close_code(), websocket_close::kGoingAway);
  EXPECT_TRUE(mute->wait_for_eof(2s)) << "closed after close_timeout even without an answer";
  stopper.join();
  EXPECT_EQ(hub().clients(), 0u);

  hub().broadcast_text(R"({"type":"ignored"})");  // a stopped hub ignores broadcasts
  WsClient late(server_->port());
  ASSERT_EQ(late.handshake(), 101);
  const auto h = late.read_frame();
  ASSERT_TRUE(h);
  EXPECT_EQ(h->close_code(), websocket_close::kGoingAway) << "a stopped hub refuses newcomers";
  EXPECT_TRUE(late.wait_for_eof());
  hub().stop();  // idempotent
}

TEST_F(WebSocketHubTest, ClientsBeyondTheLimitAreRefusedWith1013) {
  HubConfig config;
  config.max_clients = 1;
  start(config);
  auto first = connect();
  WsClient second(server_->port());
  ASSERT_EQ(second.handshake(), 101);
  const auto f = second.read_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->close_code(), websocket_close::kTryAgainLater);
  EXPECT_TRUE(second.wait_for_eof());
  EXPECT_EQ(hub().clients(), 1u);
}

TEST_F(WebSocketHubTest, ConcurrentBroadcastsArriveWholeAndInOrderPerThread) {
  start();
  auto a = connect();
  auto b = connect();
  constexpr int kThreads = 4;
  constexpr int kEach = 200;
  std::vector<std::thread> senders;
  for (int t = 0; t < kThreads; ++t) {
    senders.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        hub().broadcast_text(nlohmann::json{{"t", t}, {"i", i}}.dump());
        if (i % 50 == 0) hub().broadcast_binary(2, static_cast<std::uint32_t>(i), "chunk");
      }
    });
  }
  for (WsClient* c : {a.get(), b.get()}) {
    std::vector<int> next(kThreads, 0);
    int texts = 0;
    while (texts < kThreads * kEach) {
      const auto f = c->read_data_frame();
      ASSERT_TRUE(f) << "after " << texts << " events";
      if (f->opcode != kText) continue;
      const auto j = nlohmann::json::parse(f->payload);
      EXPECT_EQ(j["i"], next[j["t"].get<int>()]++);
      ++texts;
    }
  }
  for (auto& s : senders) s.join();
  EXPECT_EQ(hub().stats().binary_frames_dropped, 0u) << "clients that keep up lose nothing";
}

TEST(WebSocketHub, RejectsBroadcastsThatCouldNeverBeDelivered) {
  HubConfig config;
  config.max_queued_text_bytes = 4096;
  config.max_queued_binary_bytes = 8192;
  WebSocketHub hub(config);
  EXPECT_THROW(hub.broadcast_text("bad \xFF"), std::invalid_argument);
  EXPECT_THROW(hub.broadcast_text(std::string(5000, 'x')), std::length_error);
  EXPECT_THROW(hub.broadcast_binary(1, 1, std::string(9000, 'x')), std::length_error);
  EXPECT_NO_THROW(hub.broadcast_text("{}")) << "before start(): nothing to do";
  HubConfig bad;
  bad.ping_interval = 0ms;
  EXPECT_THROW(WebSocketHub{bad}, std::invalid_argument);
}

TEST(WebSocketHub, StartTwiceOrAfterStopThrows) {
  WebSocketHub hub(HubConfig{});
  hub.start();
  EXPECT_THROW(hub.start(), std::logic_error);
  hub.stop();
  EXPECT_THROW(hub.start(), std::logic_error);
}

TEST(WebSocketHub, StopFromOnMessageThrowsInsteadOfDeadlocking) {
  std::unique_ptr<WebSocketHub> hub;
  std::atomic<bool> threw{false};
  HubConfig config;
  config.close_timeout = 200ms;
  config.on_message = [&](std::uint64_t, std::string_view, std::string) {
    try {
      hub->stop();
    } catch (const std::logic_error&) {
      threw = true;
    }
  };
  hub = std::make_unique<WebSocketHub>(config);
  hub->start();
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, sv), 0);
  hub->adopt("pair")(sv[0], client_frame(kText, "stop please"));
  EXPECT_TRUE(eventually([&] { return threw.load(); }));
  hub->stop();
  ::close(sv[1]);
}

TEST(WebSocketHub, HandlerOutlivingTheHubClosesTheSocketWith1001) {
  UpgradeHandler handler;
  {
    WebSocketHub hub(HubConfig{});
    hub.start();
    handler = hub.adopt("late client");
  }
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, sv), 0);
  handler(sv[0], "");
  char buf[256];
  const ssize_t n = ::recv(sv[1], buf, sizeof(buf), 0);
  ASSERT_GT(n, 0);
  ServerFrame f;
  ASSERT_EQ(test::decode_server_frame(std::string_view(buf, static_cast<std::size_t>(n)), f),
            static_cast<std::size_t>(n));
  EXPECT_EQ(f.opcode, kClose);
  EXPECT_EQ(f.close_code(), websocket_close::kGoingAway);
  EXPECT_EQ(::recv(sv[1], buf, sizeof(buf), 0), 0) << "and the socket is closed";
  ::close(sv[1]);
}

}  // namespace
}  // namespace scanplan::http
