// The terminal operator's failures: each HTTP status and transport problem becomes the message
// and exit code that docs/cli.md promises.
#include <gtest/gtest.h>

#include <string>

#include "exit_codes.hpp"
#include "http/unique_fd.hpp"
#include "operator_error.hpp"
#include "server_url.hpp"
#include "tcp_connect.hpp"

#include <netinet/in.h>
#include <sys/socket.h>

namespace scanplan::cli {
namespace {

std::string error_body(const std::string& code, const std::string& message) {
  return R"({"error":{"code":")" + code + R"(","message":")" + message + R"("}})";
}

TEST(OperatorError, TokenRefusedSaysSoAndHowToFixIt) {
  const OperatorError e =
      error_for_status(401, error_body("unauthorized", "a valid token is required"),
                       "read the session", "http://127.0.0.1:8080");
  EXPECT_EQ(e.code(), ExitCode::kBadToken);
  EXPECT_EQ(to_int(e.code()), 3);
  const std::string m = e.what();
  EXPECT_NE(m.find("the server refused the token (HTTP 401)"), std::string::npos) << m;
  EXPECT_NE(m.find("a valid token is required"), std::string::npos) << m;
  EXPECT_NE(m.find("--token"), std::string::npos) << m;
}

TEST(OperatorError, ViewerActingGetsTheServersWordsAndCode4) {
  const OperatorError e = error_for_status(
      403, error_body("forbidden", "this action needs an operator token; yours is a viewer's"),
      "approve candidate 12", "http://s");
  EXPECT_EQ(e.code(), ExitCode::kForbidden);
  EXPECT_STREQ(e.what(),
               "cannot approve candidate 12 (HTTP 403): this action needs an operator token; "
               "yours is a viewer's");
}

TEST(OperatorError, EachStatusHasItsOwnExitCode) {
  const auto code = [](int status) {
    return to_int(error_for_status(status, error_body("x", "why"), "act", "http://s").code());
  };
  EXPECT_EQ(code(400), 9);
  EXPECT_EQ(code(404), 5);
  EXPECT_EQ(code(409), 6);
  EXPECT_EQ(code(413), 9);
  EXPECT_EQ(code(500), 7);
  EXPECT_EQ(code(503), 7);
  EXPECT_STREQ(error_for_status(404, error_body("not_found", "no candidate 99 in the current plan"),
                                "approve candidate 99", "http://s")
                   .what(),
               "cannot approve candidate 99 (HTTP 404): no candidate 99 in the current plan");
}

TEST(OperatorError, ABodyThatIsNotTheJsonErrorIsQuotedShortAndOnOneLine) {
  const OperatorError e =
      error_for_status(502, "<html>\nBad gateway\n</html>", "read the session", "http://s");
  EXPECT_EQ(e.code(), ExitCode::kServerFailure);
  EXPECT_STREQ(e.what(), "cannot read the session (HTTP 502): <html> Bad gateway </html>");
  EXPECT_NE(std::string(error_for_status(500, "", "act", "http://s").what()).find("no details"),
            std::string::npos);
  EXPECT_LT(std::string(error_for_status(500, std::string(5000, 'x'), "act", "h").what()).size(),
            250u)
      << "a long body is cut";
}

TEST(OperatorError, TransportProblemsMapToUnreachableOrFailure) {
  EXPECT_EQ(error_for_transport(HttpClientError(HttpClientError::Kind::kUnreachable, "x")).code(),
            ExitCode::kUnreachable);
  EXPECT_EQ(error_for_transport(HttpClientError(HttpClientError::Kind::kNoAnswer, "x")).code(),
            ExitCode::kUnreachable);
  EXPECT_EQ(error_for_transport(HttpClientError(HttpClientError::Kind::kBadUrl, "x")).code(),
            ExitCode::kFailure);
  const OperatorError e =
      error_for_transport(HttpClientError(HttpClientError::Kind::kNotHttp, "not HTTP"));
  EXPECT_EQ(e.code(), ExitCode::kFailure);
  EXPECT_NE(std::string(e.what()).find("is that address scanplan-server?"), std::string::npos);
}

TEST(OperatorError, HelpListsEveryExitCode) {
  const std::string help = exit_code_help();
  for (int c = 0; c <= 9; ++c) {
    EXPECT_NE(help.find("\n  " + std::to_string(c) + "  "), std::string::npos) << c;
  }
}

TEST(ServerUrl, ParsesHostPortAndDefaults) {
  ServerUrl u = parse_server_url("http://127.0.0.1:8080/");
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, "8080");
  EXPECT_EQ(u.base, "http://127.0.0.1:8080");
  u = parse_server_url("http://robot-base");
  EXPECT_EQ(u.port, "80");
  u = parse_server_url("http://[::1]:9000");
  EXPECT_EQ(u.host, "::1");
  EXPECT_EQ(u.port, "9000");
}

TEST(ServerUrl, RefusesWhatCannotWork) {
  for (const char* bad : {"https://x:1", "127.0.0.1:8080", "http://:8080", "http://x:99999",
                          "http://x:port", "http://[::1"}) {
    try {
      parse_server_url(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const HttpClientError& e) {
      EXPECT_EQ(e.kind(), HttpClientError::Kind::kBadUrl) << bad;
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(TcpConnect, AClosedPortSaysConnectionRefusedAndAsksWhetherTheServerRuns) {
  // A port that was just free: bind, read it back, close.
  http::UniqueFd s(::socket(AF_INET, SOCK_STREAM, 0));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(s.get(), reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(::getsockname(s.get(), reinterpret_cast<sockaddr*>(&a), &len), 0);
  const std::string url = "http://127.0.0.1:" + std::to_string(ntohs(a.sin_port));
  s.reset();
  try {
    connect_tcp(parse_server_url(url), std::chrono::seconds(2));
    FAIL() << "connected to a closed port";
  } catch (const HttpClientError& e) {
    EXPECT_EQ(e.kind(), HttpClientError::Kind::kUnreachable);
    EXPECT_EQ(std::string(e.what()),
              "cannot reach " + url + ": connection refused — is scanplan-server running?");
  }
}

}  // namespace
}  // namespace scanplan::cli
