#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "http/http_error.hpp"
#include "http/router.hpp"

namespace scanplan::http {
namespace {

Request make_request(std::string method, std::string target) {
  Request r;
  r.method = std::move(method);
  r.target = std::move(target);
  r.path = r.target.substr(0, r.target.find('?'));
  return r;
}

Router::Handler echo(std::string name) {
  return [name](const Request&, const Router::Params& params) {
    nlohmann::json j = {{"route", name}, {"params", params}};
    return Response::json(200, j);
  };
}

nlohmann::json body_of(const Response& r) {
  return nlohmann::json::parse(r.body);
}

class HttpRouterTest : public ::testing::Test {
 protected:
  HttpRouterTest() : router_([this](std::string_view m) { logged_.emplace_back(m); }) {
    router_.add("GET", "/api/v1/health", echo("health"));
    router_.add("GET", "/api/v1/scans", echo("list"));
    router_.add("POST", "/api/v1/scans", echo("create"));
    router_.add("GET", "/api/v1/scans/{id}", echo("scan"));
    router_.add("GET", "/api/v1/scans/latest", echo("latest"));  // after {id} on purpose
    router_.add("POST", "/api/v1/candidates/{id}/approve", echo("approve"));
    router_.add("GET", "/api/v1/layers/{layer}.png", echo("layer"));
    router_.add("GET", "/api/v1/throw", [](const Request&, const Router::Params&) -> Response {
      throw std::runtime_error("secret database detail");
    });
    router_.add("GET", "/api/v1/teapot", [](const Request&, const Router::Params&) -> Response {
      throw HttpError(422, "unprocessable", "x must be a number");
    });
  }

  Router router_;
  std::vector<std::string> logged_;
};

TEST_F(HttpRouterTest, MatchesLiteralRoutes) {
  const Response r = router_.route(make_request("GET", "/api/v1/health?x=1"));
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(body_of(r)["route"], "health");
}

TEST_F(HttpRouterTest, CapturesParametersPerSegment) {
  const Response r = router_.route(make_request("GET", "/api/v1/scans/a%2Fb%20c"));
  EXPECT_EQ(body_of(r)["route"], "scan");
  EXPECT_EQ(body_of(r)["params"]["id"], "a/b c");
  const Response approve = router_.route(make_request("POST", "/api/v1/candidates/42/approve"));
  EXPECT_EQ(body_of(approve)["params"]["id"], "42");
}

TEST_F(HttpRouterTest, LiteralBeatsCaptureRegardlessOfOrder) {
  EXPECT_EQ(body_of(router_.route(make_request("GET", "/api/v1/scans/latest")))["route"], "latest");
  EXPECT_EQ(body_of(router_.route(make_request("GET", "/api/v1/scans/7")))["route"], "scan");
}

TEST_F(HttpRouterTest, CaptureWithSuffix) {
  const Response r = router_.route(make_request("GET", "/api/v1/layers/regions.png"));
  EXPECT_EQ(body_of(r)["params"]["layer"], "regions");
  EXPECT_EQ(router_.route(make_request("GET", "/api/v1/layers/.png")).status, 404);
  EXPECT_EQ(router_.route(make_request("GET", "/api/v1/layers/regions.jpg")).status, 404);
}

TEST_F(HttpRouterTest, UnknownPathIsJson404) {
  const Response r = router_.route(make_request("GET", "/api/v1/nope"));
  EXPECT_EQ(r.status, 404);
  EXPECT_EQ(body_of(r)["error"]["code"], "not_found");
  EXPECT_EQ(router_.route(make_request("GET", "/api/v1/scans/")).status, 404);
  EXPECT_EQ(router_.route(make_request("GET", "/api/v1/scans/1/2")).status, 404);
}

TEST_F(HttpRouterTest, WrongMethodIsJson405WithAllow) {
  const Response r = router_.route(make_request("DELETE", "/api/v1/scans"));
  EXPECT_EQ(r.status, 405);
  EXPECT_EQ(body_of(r)["error"]["code"], "method_not_allowed");
  EXPECT_EQ(r.header("Allow"), "GET, POST, HEAD");
  const Response health = router_.route(make_request("POST", "/api/v1/health"));
  EXPECT_EQ(health.header("Allow"), "GET, HEAD");
}

TEST_F(HttpRouterTest, HeadFallsBackToGet) {
  const Response r = router_.route(make_request("HEAD", "/api/v1/scans/3"));
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(body_of(r)["route"], "scan");
}

TEST_F(HttpRouterTest, ThrowingHandlerIs500WithoutDetails) {
  const Response r = router_.route(make_request("GET", "/api/v1/throw"));
  EXPECT_EQ(r.status, 500);
  EXPECT_EQ(body_of(r)["error"]["code"], "internal");
  EXPECT_EQ(r.body.find("secret"), std::string::npos);
  ASSERT_EQ(logged_.size(), 1u);
  EXPECT_NE(logged_[0].find("secret database detail"), std::string::npos);
  EXPECT_NE(logged_[0].find("/api/v1/throw"), std::string::npos);
}

TEST_F(HttpRouterTest, HttpErrorKeepsItsStatusAndMessage) {
  const Response r = router_.route(make_request("GET", "/api/v1/teapot"));
  EXPECT_EQ(r.status, 422);
  EXPECT_EQ(body_of(r)["error"]["code"], "unprocessable");
  EXPECT_EQ(body_of(r)["error"]["message"], "x must be a number");
}

TEST_F(HttpRouterTest, FallbackHandlesUnknownPaths) {
  router_.set_fallback([](const Request& r, const Router::Params& params) {
    EXPECT_TRUE(params.empty());
    return Response::bytes("static " + r.path, "text/plain");
  });
  const Response r = router_.route(make_request("GET", "/index.html"));
  EXPECT_EQ(r.body, "static /index.html");
  // Known paths still get their 405 rather than the fallback.
  EXPECT_EQ(router_.route(make_request("PUT", "/api/v1/health")).status, 405);
}

TEST_F(HttpRouterTest, RootPattern) {
  router_.add("GET", "/", echo("root"));
  EXPECT_EQ(body_of(router_.route(make_request("GET", "/")))["route"], "root");
}

TEST(HttpRouter, RejectsBadPatterns) {
  Router router([](std::string_view) {});
  const auto h = echo("x");
  EXPECT_THROW(router.add("GET", "api/v1", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "/a/{}", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "/a/{x", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "/a/x}", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "/a/{x}{y}", h), std::invalid_argument);
  EXPECT_THROW(router.add("", "/a", h), std::invalid_argument);
  EXPECT_THROW(router.add("GET", "/a", nullptr), std::invalid_argument);
  router.add("GET", "/a/{x}", h);
  EXPECT_THROW(router.add("GET", "/a/{x}", h), std::invalid_argument);
}

}  // namespace
}  // namespace scanplan::http
