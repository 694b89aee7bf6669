#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "http/http_server.hpp"
#include "http/router.hpp"
#include "http/static_files.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace scanplan::http {
namespace {

struct ClientResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;

  nlohmann::json json() const { return nlohmann::json::parse(body); }
  std::string header(const std::string& lower_name) const {
    const auto it = headers.find(lower_name);
    return it == headers.end() ? std::string() : it->second;
  }
};

// A blocking loopback client that reads responses the simple way (Content-Length framing).
class Client {
 public:
  explicit Client(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
    timeval tv{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  }
  ~Client() { close(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  bool connected() const { return connected_; }

  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  // Closes with RST instead of FIN, like a client that crashed.
  void abort() {
    linger l{1, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof(l));
    close();
  }

  bool send(std::string_view data) {
    while (!data.empty()) {
      const ssize_t n = ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL);
      if (n <= 0) return false;
      data.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
  }

  // One response, or nullopt when the connection ends (or times out) first.
  std::optional<ClientResponse> read_response(bool head_request = false) {
    std::size_t head_end;
    while ((head_end = buffer_.find("\r\n\r\n")) == std::string::npos) {
      if (!fill()) return std::nullopt;
    }
    ClientResponse r;
    const std::string head = buffer_.substr(0, head_end);
    buffer_.erase(0, head_end + 4);
    std::size_t line_end = head.find("\r\n");
    const std::string status_line = head.substr(0, line_end);
    if (status_line.rfind("HTTP/1.1 ", 0) != 0) return std::nullopt;
    r.status = std::stoi(status_line.substr(9, 3));
    while (line_end != std::string::npos) {
      const std::size_t start = line_end + 2;
      line_end = head.find("\r\n", start);
      const std::string line =
          head.substr(start, line_end == std::string::npos ? std::string::npos : line_end - start);
      const std::size_t colon = line.find(':');
      if (colon == std::string::npos) continue;
      std::string name = line.substr(0, colon);
      for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      r.headers[name] = line.substr(line.find_first_not_of(' ', colon + 1));
    }
    const std::size_t length =
        head_request || r.header("content-length").empty()
            ? 0
            : static_cast<std::size_t>(std::stoull(r.header("content-length")));
    while (buffer_.size() < length) {
      if (!fill()) return std::nullopt;
    }
    r.body = buffer_.substr(0, length);
    buffer_.erase(0, length);
    return r;
  }

  // Everything until the server closes the connection, raw.
  std::string read_to_end() {
    while (fill()) {
    }
    return std::exchange(buffer_, std::string());
  }

  // True when the server closes the connection without sending anything more.
  bool closed_by_server() {
    if (!buffer_.empty()) return false;
    char c;
    const ssize_t n = ::recv(fd_, &c, 1, 0);
    return n == 0 || (n < 0 && errno == ECONNRESET);
  }

  ClientResponse request(const std::string& method, const std::string& target,
                         const std::string& body = "", const std::string& extra_headers = "") {
    std::string text = method + " " + target + " HTTP/1.1\r\nHost: test\r\n" + extra_headers;
    if (!body.empty()) text += "Content-Length: " + std::to_string(body.size()) + "\r\n";
    text += "\r\n" + body;
    EXPECT_TRUE(send(text));
    auto r = read_response(method == "HEAD");
    EXPECT_TRUE(r.has_value()) << method << " " << target << ": no response";
    return r.value_or(ClientResponse{});
  }

 private:
  bool fill() {
    char chunk[65536];
    const ssize_t n = ::recv(fd_, chunk, sizeof(chunk), 0);
    if (n <= 0) return false;
    buffer_.append(chunk, static_cast<std::size_t>(n));
    return true;
  }

  int fd_;
  bool connected_ = false;
  std::string buffer_;
};

// A server on an ephemeral loopback port running on its own thread.
class RunningServer {
 public:
  RunningServer(HttpServer::Handler handler, Limits limits = {},
                decltype(ServerConfig::admit) admit = {}) {
    ServerConfig config;
    config.host = "127.0.0.1";
    config.port = 0;
    config.limits = limits;
    config.admit = std::move(admit);
    config.log = [this](std::string_view m) {
      const std::lock_guard lock(log_mutex_);
      log_ += std::string(m) + "\n";
    };
    server_ = std::make_unique<HttpServer>(std::move(config), std::move(handler));
    server_->start();
    thread_ = std::thread([this] {
      try {
        server_->run();
      } catch (const std::exception& e) {
        ADD_FAILURE() << "run() threw: " << e.what();
      }
    });
  }
  ~RunningServer() {
    server_->stop();
    thread_.join();
  }

  HttpServer& server() { return *server_; }
  std::uint16_t port() const { return server_->port(); }
  std::string log() {
    const std::lock_guard lock(log_mutex_);
    return log_;
  }

 private:
  std::unique_ptr<HttpServer> server_;
  std::thread thread_;
  std::mutex log_mutex_;
  std::string log_;
};

std::string big_body(std::size_t size) {
  std::string s(size, '\0');
  for (std::size_t i = 0; i < size; ++i) s[i] = static_cast<char>('a' + i % 26);
  return s;
}

// The REST-ish application used by most tests: a router with a static-file fallback.
class HttpServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() /
           ("scanplan_http_server_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir_ / "web");
    std::ofstream(dir_ / "secret.txt") << "TOP SECRET";
    std::ofstream(dir_ / "web" / "index.html") << "<html>scanplan</html>";
    std::ofstream(dir_ / "web" / "app.js") << "console.log('hi')";

    router_ = std::make_shared<Router>([](std::string_view) {});
    router_->add("GET", "/api/v1/health", [](const Request&, const Router::Params&) {
      return Response::json(200, {{"status", "ok"}});
    });
    router_->add("GET", "/api/v1/scans/{id}", [](const Request&, const Router::Params& p) {
      return Response::json(200, {{"id", p.at("id")}});
    });
    router_->add("POST", "/api/v1/scans", [](const Request& r, const Router::Params&) {
      const auto x = r.query.find("x");
      return Response::json(
          201,
          {{"bytes", r.body.size()}, {"x", x == r.query.end() ? "" : x->second}, {"peer", r.peer}});
    });
    router_->add("GET", "/api/v1/big", [](const Request&, const Router::Params&) {
      return Response::bytes(big_body(8 << 20), "application/octet-stream");
    });
    router_->add("GET", "/api/v1/throw", [](const Request&, const Router::Params&) -> Response {
      throw std::runtime_error("secret detail");
    });
    auto files = std::make_shared<StaticFiles>(dir_ / "web");
    router_->set_fallback(
        [files](const Request& r, const Router::Params&) { return files->serve(r); });
  }
  void TearDown() override {
    server_.reset();
    fs::remove_all(dir_);
  }

  void start(Limits limits = {}, decltype(ServerConfig::admit) admit = {}) {
    auto router = router_;
    server_ = std::make_unique<RunningServer>(
        [router, this](const Request& r) {
          ++handled_;
          return router->route(r);
        },
        limits, std::move(admit));
  }
  std::atomic<int> handled_{0};
  std::uint16_t port() const { return server_->port(); }

  fs::path dir_;
  std::shared_ptr<Router> router_;
  std::unique_ptr<RunningServer> server_;
};

TEST_F(HttpServerTest, KeepAliveServesTwoRequestsOnOneConnection) {
  start();
  Client c(port());
  ASSERT_TRUE(c.connected());
  const auto first = c.request("GET", "/api/v1/health");
  EXPECT_EQ(first.status, 200);
  EXPECT_EQ(first.json()["status"], "ok");
  EXPECT_EQ(first.header("content-type"), "application/json");
  EXPECT_TRUE(first.header("connection").empty());
  const auto second = c.request("GET", "/api/v1/scans/12");
  EXPECT_EQ(second.status, 200);
  EXPECT_EQ(second.json()["id"], "12");
}

TEST_F(HttpServerTest, PipelinedRequestsAreAnsweredInOrder) {
  start();
  Client c(port());
  std::string batch;
  for (int i = 0; i < 20; ++i) {
    batch += "GET /api/v1/scans/" + std::to_string(i) + " HTTP/1.1\r\nHost: t\r\n\r\n";
  }
  batch += "POST /api/v1/scans?x=2.5 HTTP/1.1\r\nHost: t\r\nContent-Length: 3\r\n\r\nabc";
  ASSERT_TRUE(c.send(batch));
  for (int i = 0; i < 20; ++i) {
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->json()["id"], std::to_string(i));
  }
  const auto post = c.read_response();
  ASSERT_TRUE(post.has_value());
  EXPECT_EQ(post->status, 201);
  EXPECT_EQ(post->json()["bytes"], 3);
  EXPECT_EQ(post->json()["x"], "2.5");
  EXPECT_EQ(post->json()["peer"].get<std::string>().rfind("127.0.0.1:", 0), 0u);
}

TEST_F(HttpServerTest, DeepPipelineWithBackpressure) {
  Limits limits;
  limits.max_pipelined = 2;
  start(limits);
  Client c(port());
  std::string batch;
  for (int i = 0; i < 200; ++i) {
    batch += "GET /api/v1/scans/" + std::to_string(i) + " HTTP/1.1\r\nHost: t\r\n\r\n";
  }
  ASSERT_TRUE(c.send(batch));
  for (int i = 0; i < 200; ++i) {
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value()) << i;
    ASSERT_EQ(r->json()["id"], std::to_string(i));
  }
}

TEST_F(HttpServerTest, UnknownPathAndWrongMethodAreJsonErrors) {
  start();
  Client c(port());
  const auto missing = c.request("GET", "/api/v1/nothing-here");
  EXPECT_EQ(missing.status, 404);
  EXPECT_EQ(missing.json()["error"]["code"], "not_found");
  const auto wrong = c.request("DELETE", "/api/v1/health");
  EXPECT_EQ(wrong.status, 405);
  EXPECT_EQ(wrong.json()["error"]["code"], "method_not_allowed");
  EXPECT_EQ(wrong.header("allow"), "GET, HEAD");
  EXPECT_EQ(c.request("GET", "/api/v1/health").status, 200) << "errors keep the connection";
}

TEST_F(HttpServerTest, HeadSendsHeadersOnly) {
  start();
  Client c(port());
  const auto head = c.request("HEAD", "/api/v1/health");
  EXPECT_EQ(head.status, 200);
  EXPECT_EQ(head.header("content-length"), "15");
  EXPECT_TRUE(head.body.empty());
  EXPECT_EQ(c.request("GET", "/api/v1/health").body, R"({"status":"ok"})");
}

TEST_F(HttpServerTest, ServesStaticFilesAndRefusesTraversal) {
  start();
  Client c(port());
  const auto index = c.request("GET", "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_EQ(index.body, "<html>scanplan</html>");
  EXPECT_EQ(index.header("cache-control"), "no-cache");
  EXPECT_EQ(c.request("GET", "/app.js").header("content-type"), "text/javascript; charset=utf-8");

  for (const char* attack :
       {"/../etc/passwd", "/../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E/%2e%2e/etc/passwd",
        "/..%2fsecret.txt", "/app.js/..%2F..%2Fsecret.txt", "/index.html%00.js",
        "/./../secret.txt"}) {
    Client a(port());
    const auto r = a.request("GET", attack);
    EXPECT_TRUE(r.status == 400 || r.status == 404) << attack << " -> " << r.status;
    EXPECT_EQ(r.body.find("TOP SECRET"), std::string::npos) << attack;
    EXPECT_NO_THROW(static_cast<void>(r.json())) << attack;
  }
}

TEST_F(HttpServerTest, HandlerExceptionIs500AndServerKeepsRunning) {
  start();
  Client c(port());
  const auto r = c.request("GET", "/api/v1/throw");
  EXPECT_EQ(r.status, 500);
  EXPECT_EQ(r.json()["error"]["code"], "internal");
  EXPECT_EQ(r.body.find("secret detail"), std::string::npos);
  EXPECT_EQ(c.request("GET", "/api/v1/health").status, 200);
}

TEST_F(HttpServerTest, MalformedRequestGetsJsonErrorThenClose) {
  start();
  Client c(port());
  ASSERT_TRUE(c.send("THIS IS NOT HTTP\r\n\r\n"));
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(r->json()["error"]["code"], "bad_request");
  EXPECT_EQ(r->header("connection"), "close");
  EXPECT_TRUE(c.closed_by_server());
}

TEST_F(HttpServerTest, ParserLimitsReachTheClient) {
  Limits limits;
  limits.max_header_bytes = 2048;
  limits.max_body_bytes = 1000;
  start(limits);
  {
    Client c(port());
    ASSERT_TRUE(
        c.send("GET / HTTP/1.1\r\nHost: t\r\nX-Big: " + std::string(4000, 'x') + "\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 431);
    EXPECT_EQ(r->json()["error"]["code"], "header_fields_too_large");
    EXPECT_TRUE(c.closed_by_server());
  }
  {
    Client c(port());
    ASSERT_TRUE(c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 5000\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 413);
    EXPECT_NE(r->json()["error"]["message"].get<std::string>().find("1000"), std::string::npos);
  }
  {
    Client c(port());
    ASSERT_TRUE(c.send("GET / HTTP/1.1\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 400);
  }
  {
    Client c(port());
    ASSERT_TRUE(c.send("GET / HTTP/3.0\r\nHost: t\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 505);
  }
}

TEST_F(HttpServerTest, ChunkedUpload) {
  start();
  Client c(port());
  ASSERT_TRUE(
      c.send("POST /api/v1/scans?x=1 HTTP/1.1\r\nHost: t\r\nTransfer-Encoding: chunked\r\n\r\n"
             "3\r\nabc\r\n"));
  std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(c.send("4;ext=1\r\ndefg\r\n0\r\nX-T: 1\r\n\r\n"));
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 201);
  EXPECT_EQ(r->json()["bytes"], 7);
}

TEST_F(HttpServerTest, LargeUploadAndDownload) {
  start();
  Client c(port());
  const std::string body = big_body(6 << 20);
  const auto up = c.request("POST", "/api/v1/scans", body);
  EXPECT_EQ(up.status, 201);
  EXPECT_EQ(up.json()["bytes"], body.size());

  // Let the server hit a full socket buffer and fall back to EPOLLOUT before reading.
  ASSERT_TRUE(c.send("GET /api/v1/big HTTP/1.1\r\nHost: t\r\n\r\n"));
  std::this_thread::sleep_for(100ms);
  Client other(port());
  EXPECT_EQ(other.request("GET", "/api/v1/health").status, 200)
      << "a slow reader must not block other clients";
  const auto down = c.read_response();
  ASSERT_TRUE(down.has_value());
  EXPECT_EQ(down->body.size(), 8u << 20);
  EXPECT_TRUE(down->body == big_body(8 << 20));
}

TEST_F(HttpServerTest, ClientVanishingMidResponseDoesNotKillTheServer) {
  start();
  for (int i = 0; i < 3; ++i) {
    Client c(port());
    ASSERT_TRUE(c.send("GET /api/v1/big HTTP/1.1\r\nHost: t\r\n\r\n"));
    std::this_thread::sleep_for(20ms);
    c.abort();
  }
  std::this_thread::sleep_for(50ms);
  Client c(port());
  EXPECT_EQ(c.request("GET", "/api/v1/health").status, 200);
}

TEST_F(HttpServerTest, ExpectContinue) {
  start();
  Client c(port());
  ASSERT_TRUE(
      c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 5\r\nExpect: "
             "100-continue\r\n\r\n"));
  const auto interim = c.read_response();
  ASSERT_TRUE(interim.has_value());
  EXPECT_EQ(interim->status, 100);
  ASSERT_TRUE(c.send("hello"));
  const auto final_response = c.read_response();
  ASSERT_TRUE(final_response.has_value());
  EXPECT_EQ(final_response->status, 201);
  EXPECT_EQ(final_response->json()["bytes"], 5);
}

TEST_F(HttpServerTest, ExpectContinueRefusedBodyGets413Directly) {
  Limits limits;
  limits.max_body_bytes = 10;
  start(limits);
  Client c(port());
  ASSERT_TRUE(
      c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 50\r\nExpect: "
             "100-continue\r\n\r\n"));
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 413);
}

// Refuses any request with a body that does not say "Authorization: Bearer ok".
std::optional<Response> token_check(const Request& head) {
  if (!head.header("Content-Length") || head.header("Authorization") == "Bearer ok") {
    return std::nullopt;
  }
  return Response::error(401, "unauthorized", "no token");
}

TEST_F(HttpServerTest, AdmissionIsDecidedBeforeTheBodyOrContinue) {
  start({}, token_check);
  {
    // A 200 MB upload without a token: refused as soon as the headers are in, no 100 Continue,
    // the body never read, the handler never run.
    Client c(port());
    ASSERT_TRUE(
        c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 200000000\r\nExpect: "
               "100-continue\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 401);
    EXPECT_TRUE(c.closed_by_server());
  }
  {
    // Without Expect the client sends on; the answer still comes before the body is in.
    Client c(port());
    ASSERT_TRUE(
        c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 200000000\r\n\r\n" +
               big_body(1 << 16)));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 401);
  }
  EXPECT_EQ(handled_.load(), 0);
  Client ok(port());
  const auto r = ok.request("POST", "/api/v1/scans", "hello", "Authorization: Bearer ok\r\n");
  EXPECT_EQ(r.status, 201);
  EXPECT_EQ(r.json()["bytes"], 5);
  EXPECT_EQ(ok.request("GET", "/api/v1/health").status, 200) << "bodyless requests pass";
}

TEST_F(HttpServerTest, ABodyTricklingBelowTheMinimumRateGets408) {
  Limits limits;
  limits.min_body_bytes_per_s = 1000;
  limits.body_grace = 300ms;
  start(limits);
  Client c(port());
  ASSERT_TRUE(c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 100000\r\n\r\n"));
  // 10 bytes every 100 ms: never a stall (body_timeout keeps resetting), but 100 bytes/s.
  const auto started = std::chrono::steady_clock::now();
  std::atomic<bool> answered{false};
  std::thread trickle([&] {
    for (int i = 0; i < 30 && !answered; ++i) {
      std::this_thread::sleep_for(100ms);
      if (!c.send("0123456789")) break;
    }
  });
  const auto r = c.read_response();
  answered = true;
  trickle.join();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 408);
  EXPECT_NE(r->json()["error"]["message"].get<std::string>().find("slower than 1000 bytes/s"),
            std::string::npos);
  // The grace period and the few bytes' allowance, not the 30 s of trickle a stall would allow.
  EXPECT_LT(std::chrono::steady_clock::now() - started, 1500ms);
}

TEST_F(HttpServerTest, ABodyAtTheMinimumRateIsReceived) {
  Limits limits;
  limits.min_body_bytes_per_s = 1000;
  limits.body_grace = 200ms;
  start(limits);
  Client c(port());
  ASSERT_TRUE(c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 1000\r\n\r\n"));
  for (int i = 0; i < 5; ++i) {
    std::this_thread::sleep_for(100ms);
    ASSERT_TRUE(c.send(big_body(200)));  // 2000 bytes/s
  }
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 201);
}

// Two clients a server limited to two connections serves, and what a third one is told.
struct ThirdConnection {
  std::unique_ptr<Client> a, b, c;
  ClientResponse refusal;
};
ThirdConnection third_connection(std::uint16_t port) {
  ThirdConnection t{std::make_unique<Client>(port), std::make_unique<Client>(port), nullptr, {}};
  EXPECT_EQ(t.a->request("GET", "/api/v1/health").status, 200);
  EXPECT_EQ(t.b->request("GET", "/api/v1/health").status, 200);
  t.c = std::make_unique<Client>(port);
  const auto r = t.c->read_response();
  EXPECT_TRUE(r.has_value());
  t.refusal = r.value_or(ClientResponse{});
  return t;
}

TEST_F(HttpServerTest, OneAddressCannotTakeEveryConnection) {
  Limits limits;
  limits.max_connections_per_address = 2;
  start(limits);
  auto [a, b, c, r] = third_connection(port());
  EXPECT_EQ(r.status, 503);
  EXPECT_NE(r.json()["error"]["message"].get<std::string>().find("this address already holds 2"),
            std::string::npos);
  b->close();
  c->close();  // refused, it held its place until it went
  std::this_thread::sleep_for(100ms);
  Client d(port());
  EXPECT_EQ(d.request("GET", "/api/v1/health").status, 200)
      << "a closed connection frees its place";
}

TEST_F(HttpServerTest, UnreadResponsesAreBoundedInBytes) {
  // Each response is 8 MB; with a 16 MB cap the server stops reading the pipeline after two,
  // however many requests wait, until the client reads.
  Limits limits;
  limits.max_queued_bytes = 16 << 20;
  start(limits);
  Client c(port());
  std::string burst;
  for (int i = 0; i < 20; ++i) burst += "GET /api/v1/big HTTP/1.1\r\nHost: t\r\n\r\n";
  ASSERT_TRUE(c.send(burst));
  std::this_thread::sleep_for(300ms);
  EXPECT_LE(handled_.load(), 4) << "requests stay unread while their answers sit unsent";
  for (int i = 0; i < 20; ++i) {
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value()) << i;
    ASSERT_EQ(r->body.size(), 8u << 20);
  }
  EXPECT_EQ(handled_.load(), 20);
}

TEST_F(HttpServerTest, SharedBodiesGoOutWhole) {
  auto blob = std::make_shared<const std::string>(big_body(3 << 20));
  router_->add("GET", "/api/v1/shared", [blob](const Request&, const Router::Params&) {
    return Response::shared(blob, "application/octet-stream");
  });
  start();
  Client c(port());
  for (int i = 0; i < 3; ++i) {
    const auto r = c.request("GET", "/api/v1/shared");
    EXPECT_EQ(r.status, 200);
    EXPECT_TRUE(r.body == *blob);
  }
  const auto head = c.request("HEAD", "/api/v1/shared");
  EXPECT_EQ(head.header("content-length"), std::to_string(3 << 20));
}

TEST_F(HttpServerTest, ConnectionCloseAndHttp10) {
  start();
  {
    Client c(port());
    const auto r = c.request("GET", "/api/v1/health", "", "Connection: close\r\n");
    EXPECT_EQ(r.header("connection"), "close");
    EXPECT_TRUE(c.closed_by_server());
  }
  {
    Client c(port());
    ASSERT_TRUE(c.send("GET /api/v1/health HTTP/1.0\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->status, 200);
    EXPECT_TRUE(c.closed_by_server());
  }
  {
    Client c(port());
    ASSERT_TRUE(c.send("GET /api/v1/health HTTP/1.0\r\nConnection: keep-alive\r\n\r\n"));
    const auto r = c.read_response();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->header("connection"), "keep-alive");
    EXPECT_EQ(c.request("GET", "/api/v1/health").status, 200);
  }
}

TEST_F(HttpServerTest, ExcessConnectionsGet503) {
  Limits limits;
  limits.max_connections = 2;
  start(limits);
  auto [a, b, c, r] = third_connection(port());
  EXPECT_EQ(r.status, 503);
  EXPECT_EQ(r.json()["error"]["code"], "service_unavailable");
  EXPECT_TRUE(c->closed_by_server());
  EXPECT_EQ(a->request("GET", "/api/v1/health").status, 200) << "existing clients unaffected";
}

TEST_F(HttpServerTest, SlowHeaderGets408) {
  Limits limits;
  limits.header_timeout = 300ms;
  start(limits);
  Client c(port());
  ASSERT_TRUE(c.send("GET /api/v1/health HTTP/1.1\r\nHost: t\r\n"));
  const auto started = std::chrono::steady_clock::now();
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 408);
  EXPECT_EQ(r->json()["error"]["code"], "request_timeout");
  EXPECT_GE(std::chrono::steady_clock::now() - started, 200ms);
  EXPECT_TRUE(c.closed_by_server());
}

TEST_F(HttpServerTest, TricklingHeaderStillTimesOut) {
  Limits limits;
  limits.header_timeout = 400ms;
  start(limits);
  Client c(port());
  const std::string head = "GET /api/v1/health HTTP/1.1\r\nHost: t\r\nX-Slow: ";
  ASSERT_TRUE(c.send(head));
  // One byte every 100 ms keeps the socket busy but the header never finishes in time.
  for (int i = 0; i < 8; ++i) {
    std::this_thread::sleep_for(100ms);
    if (!c.send("x")) break;
  }
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 408);
}

TEST_F(HttpServerTest, StalledBodyGets408) {
  Limits limits;
  limits.body_timeout = 300ms;
  start(limits);
  Client c(port());
  ASSERT_TRUE(c.send("POST /api/v1/scans HTTP/1.1\r\nHost: t\r\nContent-Length: 10\r\n\r\nabc"));
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 408);
  EXPECT_NE(r->json()["error"]["message"].get<std::string>().find("body"), std::string::npos);
}

TEST_F(HttpServerTest, IdleConnectionIsClosedSilently) {
  Limits limits;
  limits.idle_timeout = 300ms;
  limits.header_timeout = 300ms;
  start(limits);
  Client c(port());
  EXPECT_EQ(c.request("GET", "/api/v1/health").status, 200);
  EXPECT_TRUE(c.closed_by_server());  // blocks until the server gives up on us
  Client silent(port());
  EXPECT_TRUE(silent.closed_by_server()) << "a connection that never sends is closed too";
}

TEST_F(HttpServerTest, UpgradeHandsTheSocketOver) {
  std::promise<std::string> buffered;
  router_->add("GET", "/api/v1/events", [&](const Request&, const Router::Params&) {
    Response r;
    r.status = 101;
    r.set_header("Upgrade", "test");
    r.set_header("Connection", "Upgrade");
    r.on_upgrade = [&](int fd, std::string rest) {
      buffered.set_value(rest);
      const std::string greeting = "hello from the new protocol";
      ::send(fd, greeting.data(), greeting.size(), MSG_NOSIGNAL);
      ::close(fd);
    };
    return r;
  });
  start();
  Client c(port());
  ASSERT_TRUE(c.send(
      "GET /api/v1/events HTTP/1.1\r\nHost: t\r\nConnection: Upgrade\r\nUpgrade: test\r\n\r\n"
      "early bytes"));
  const auto r = c.read_response();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status, 101);
  EXPECT_EQ(r->header("connection"), "Upgrade");
  EXPECT_TRUE(r->header("content-length").empty());
  auto future = buffered.get_future();
  ASSERT_EQ(future.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(future.get(), "early bytes");
  EXPECT_EQ(c.read_to_end(), "hello from the new protocol");
}

TEST(HttpServer, StopEndsRun) {
  HttpServer server({"127.0.0.1", 0, {}, [](std::string_view) {}, false, {}},
                    [](const Request&) { return Response::json(200, {}); });
  server.start();
  EXPECT_NE(server.port(), 0);
  auto done = std::async(std::launch::async, [&] { server.run(); });
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(done.wait_for(0ms), std::future_status::timeout);
  server.stop();
  ASSERT_EQ(done.wait_for(5s), std::future_status::ready);
  done.get();
}

TEST(HttpServer, StopBeforeRunMakesRunReturn) {
  HttpServer server({"127.0.0.1", 0, {}, {}, false, {}}, [](const Request&) { return Response{}; });
  server.start();
  server.stop();
  auto done = std::async(std::launch::async, [&] { server.run(); });
  ASSERT_EQ(done.wait_for(5s), std::future_status::ready);
}

TEST(HttpServer, RunBeforeStartThrows) {
  HttpServer server({}, [](const Request&) { return Response{}; });
  EXPECT_THROW(server.run(), std::logic_error);
}

TEST(HttpServer, BusyPortGivesAClearError) {
  RunningServer first([](const Request&) { return Response{}; });
  HttpServer second({"127.0.0.1", first.port(), {}, {}, false, {}},
                    [](const Request&) { return Response{}; });
  try {
    second.start();
    FAIL() << "binding a port in use must fail";
  } catch (const std::runtime_error& e) {
    const std::string expected =
        "cannot listen on 127.0.0.1:" + std::to_string(first.port()) + ": Address already in use";
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

TEST(HttpServer, PostRunsOnTheLoopThread) {
  std::promise<std::thread::id> handler_thread;
  RunningServer running([&](const Request&) {
    handler_thread.set_value(std::this_thread::get_id());
    return Response{};
  });
  Client c(running.port());
  EXPECT_EQ(c.request("GET", "/").status, 200);
  std::promise<std::thread::id> posted_thread;
  running.server().post([&] { posted_thread.set_value(std::this_thread::get_id()); });
  auto posted = posted_thread.get_future();
  ASSERT_EQ(posted.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(posted.get(), handler_thread.get_future().get());
}

TEST(HttpServer, HandlerExceptionIsLogged) {
  RunningServer running(
      [](const Request&) -> Response { throw std::runtime_error("disk on fire"); });
  Client c(running.port());
  const auto r = c.request("GET", "/x");
  EXPECT_EQ(r.status, 500);
  EXPECT_EQ(r.body.find("disk on fire"), std::string::npos);
  EXPECT_NE(running.log().find("disk on fire"), std::string::npos);
}

// Several loops on one port (scanplan-server --http-threads): the kernel spreads connections
// over them and every loop answers; without reuse_port the port stays exclusive.
TEST(HttpServerReusePort, LoopsShareThePortAndAllServe) {
  ServerConfig config;
  config.host = "127.0.0.1";
  config.port = 0;
  config.reuse_port = true;
  config.log = [](std::string_view) {};
  std::vector<std::unique_ptr<HttpServer>> servers;
  for (int k = 0; k < 2; ++k) {
    servers.push_back(std::make_unique<HttpServer>(config, [k](const Request&) {
      return Response::json(200, {{"loop", k}});
    }));
    servers.back()->start();
    config.port = servers.front()->port();
  }
  EXPECT_EQ(servers[1]->port(), servers[0]->port());
  std::vector<std::thread> threads;
  for (auto& s : servers) threads.emplace_back([&s] { s->run(); });

  int answered[2] = {0, 0};
  for (int c = 0; c < 40; ++c) {
    Client client(config.port);
    ASSERT_TRUE(client.connected());
    const auto r = client.request("GET", "/x");
    ASSERT_EQ(r.status, 200);
    ++answered[r.json()["loop"].get<int>()];
  }
  for (auto& s : servers) s->stop();
  for (auto& t : threads) t.join();
  EXPECT_GT(answered[0], 0);
  EXPECT_GT(answered[1], 0);

  ServerConfig exclusive = config;
  exclusive.reuse_port = false;
  exclusive.port = 0;
  HttpServer first(exclusive, [](const Request&) { return Response::json(200, {}); });
  first.start();
  exclusive.port = first.port();
  HttpServer second(exclusive, [](const Request&) { return Response::json(200, {}); });
  EXPECT_THROW(second.start(), std::runtime_error);
}

}  // namespace
}  // namespace scanplan::http
