// scanplan-server: the operator workstation (DESIGN.md "Processes").
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <malloc.h>
#include <algorithm>
#include <array>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include "app/annotations.hpp"
#include "app/events.hpp"
#include "app/live_map.hpp"
#include "app/mission.hpp"
#include "app/plan_book.hpp"
#include "app/robot_board.hpp"
#include "app/scan_intake.hpp"
#include "dds/dds_link.hpp"
#include "http/http_server.hpp"
#include "http/router.hpp"
#include "http/static_files.hpp"
#include "http/websocket_hub.hpp"
#include "rest/api.hpp"
#include "rest/auth.hpp"

#ifndef SCANPLAN_DEFAULT_WEB_DIR
#define SCANPLAN_DEFAULT_WEB_DIR "web/dist"
#endif

namespace {

// The HTTP loops a signal stops; filled before the handlers are installed, then only read.
constexpr int kMaxHttpThreads = 8;
std::array<scanplan::http::HttpServer*, kMaxHttpThreads> g_servers{};
void on_signal(int) {
  for (auto* s : g_servers) {
    if (s) s->stop();
  }
}

std::string env_or_empty(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

namespace http = scanplan::http;
namespace srv = scanplan::server;

struct Options {
  std::string session_dir, listen = "127.0.0.1:8080", web_dir = SCANPLAN_DEFAULT_WEB_DIR;
  std::uint32_t domain = 0;
  // How the robots' reported poses go wrong: the pose graph weighs their odometry by it, and
  // with drift a scan's match starts from the robot's last placed scan.
  std::string odometry = "drift";
  // One event loop per core by default: the page, the terminal clients and the other robots'
  // tools poll the API while scans are processed on other threads.
  int http_threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--session", o.session_dir, "session directory")->required();
  app.add_option("--listen", o.listen, "HTTP address host:port (port 0 picks a free one)")
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain id")->capture_default_str();
  app.add_option("--web", o.web_dir, "directory of the built web page")->capture_default_str();
  app.add_option("--odometry", o.odometry,
                 "drift|absolute|exact: the robots' pose sensors: integrated odometry that "
                 "drifts with the distance driven, an absolute fix with bounded noise, or exact "
                 "poses (a total station, a simulation without noise: scans join the map where "
                 "they are reported even when no match places them)")
      ->capture_default_str()
      ->check(CLI::IsMember({"drift", "absolute", "exact"}));
  app.add_option("--http-threads", o.http_threads, "HTTP event loops sharing the port")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxHttpThreads));
}

http::ServerConfig server_config(const Options& o) {
  const auto colon = o.listen.rfind(':');
  if (colon == std::string::npos) throw std::runtime_error("--listen must be host:port");
  http::ServerConfig config;
  config.host = o.listen.substr(0, colon);
  const int port = std::stoi(o.listen.substr(colon + 1));
  if (port < 0 || port > 65535) throw std::runtime_error("--listen port must be 0..65535");
  config.port = static_cast<std::uint16_t>(port);
  // Handlers run on several loop threads at once: the API holds no state of its own and the
  // map, plans, mission, intake and hub guard theirs. The connection limit is shared among them.
  config.reuse_port = o.http_threads > 1;
  config.limits.max_connections =
      std::max<std::size_t>(1, config.limits.max_connections / o.http_threads);
  config.limits.max_connections_per_address =
      std::max<std::size_t>(1, config.limits.max_connections_per_address / o.http_threads);
  return config;
}

// Runs `count` HTTP loops on one port until a signal or a failing loop stops them.
void serve(http::ServerConfig config, int count, const http::Router& router,
           const std::function<void(std::uint16_t port)>& listening) {
  std::vector<std::unique_ptr<http::HttpServer>> servers;
  for (int k = 0; k < count; ++k) {
    servers.push_back(std::make_unique<http::HttpServer>(
        config, [&router](const http::Request& r) { return router.route(r); }));
    servers.back()->start();
    config.port = servers.front()->port();
  }
  for (std::size_t k = 0; k < servers.size(); ++k) g_servers[k] = servers[k].get();
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  try {
    listening(config.port);
  } catch (...) {
    g_servers.fill(nullptr);  // the servers go with this frame: no signal may reach them
    throw;
  }
  std::vector<std::thread> loops;
  for (std::size_t k = 1; k < servers.size(); ++k) {
    loops.emplace_back([&servers, k] {
      try {
        servers[k]->run();
      } catch (const std::exception& e) {
        spdlog::error("HTTP loop {}: {}", k, e.what());
      }
      // One loop failing takes the others down: a half-served port is worse than a clear exit.
      for (auto& s : servers) s->stop();
    });
  }
  const auto stop_loops = [&] {
    for (auto& s : servers) s->stop();
    for (auto& t : loops) t.join();
    g_servers.fill(nullptr);
  };
  try {
    servers.front()->run();
  } catch (...) {
    stop_loops();
    throw;
  }
  stop_loops();
}

// The parameters the operator last set in this session (the target region, the no-go zones, α,
// ...), so that a restarted server plans as before. Stored ones it cannot take (from a version
// that checked less) are reported and left out: the defaults are a working mission.
void resume_params(const scanplan::SessionStore& session, srv::LiveMap& map) {
  try {
    const std::optional<std::string> stored = session.latest_params();
    if (!stored) return;
    nlohmann::json j = nlohmann::json::parse(*stored);
    if (j.contains("target") && j["target"].is_null()) j.erase("target");  // the default square
    map.set_params(srv::rest::params_from(j, map.params()));
    spdlog::info("resumed the session's parameters: {}", *stored);
  } catch (const std::exception& e) {
    spdlog::warn("the session's stored parameters are not usable ({}): using the defaults",
                 e.what());
  }
}

// The whole server: storage, the application, DDS and HTTP, wired and run until stopped.
void run(const Options& o) {
  // A file-size limit (RLIMIT_FSIZE) is a full disk by another name: a write beyond it must fail
  // with EFBIG, which the session store reports, not kill the server with SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  // Flags first: a mistyped --listen must not open (or create) a session.
  http::ServerConfig config = server_config(o);
  std::string operator_token = env_or_empty("SCANPLAN_OPERATOR_TOKEN");
  const bool generated = operator_token.empty();
  if (generated) operator_token = srv::Auth::random_token();
  const srv::Auth auth(operator_token, env_or_empty("SCANPLAN_VIEWER_TOKEN"));

  scanplan::SessionStore session(o.session_dir);
  http::HubConfig hub_config;
  // A dense scan's Draco chunk is a few MB; a browser may lag one or two behind.
  hub_config.max_queued_binary_bytes = 16u << 20;
  hub_config.log = [](std::string_view msg) { spdlog::warn("events: {}", msg); };
  http::WebSocketHub hub(hub_config);
  const srv::Events events(&hub);
  srv::PlanBook plans;
  srv::RobotBoard robots;
  scanplan::MissionConfig mission_config;
  if (o.odometry == "exact") {
    mission_config.pose_noise = {0, 0, 0, scanplan::OdometryModel::kAbsolute};
  } else {
    mission_config.pose_noise.model = *scanplan::parse_odometry_model(o.odometry);
  }
  srv::LiveMap map(plans, mission_config);
  resume_params(session, map);
  srv::ScanIntake intake(session, map, events);
  srv::DdsLink dds(o.domain, robots, intake, events);
  srv::Mission mission(map, plans, robots, dds, session, events);
  srv::Annotations annotations(session, dds, events);
  dds.on_status = [&mission](const std::string& robot, const srv::RobotStatus& status) {
    mission.on_status(robot, status);
  };
  dds.on_robot_lost = [&mission](const srv::RobotLoss& loss) { mission.on_robot_lost(loss); };
  dds.on_robot_back = [&mission](const std::string& robot) { mission.on_robot_back(robot); };
  // Wired before the intake starts: the scans it reloads after a restart republish the map
  // and the plan for DDS subscribers.
  map.on_map = [&dds](const scanplan::PointCloud& points) { dds.publish_map(points); };
  map.on_plan = [&dds](const srv::PlanRecord& plan) { dds.publish_candidates(plan); };
  annotations.republish();

  srv::Api api({map, plans, robots, intake, dds, mission, annotations, hub}, auth, o.session_dir);
  http::Router router([](std::string_view msg) { spdlog::error("{}", msg); });
  api.install(router);
  config.admit = [&api](const http::Request& head) { return api.admit(head); };
  const http::StaticFiles files(o.web_dir);
  router.set_fallback(
      [&files](const http::Request& r, const http::Router::Params&) { return files.serve(r); });

  serve(config, o.http_threads, router, [&](std::uint16_t port) {
    hub.start();
    intake.start();
    dds.start();
    const std::string url = "http://" + config.host + ":" + std::to_string(port) + "/";
    std::cout << "scanplan-server listening on " << url << std::endl;
    if (generated)
      std::cout << "operator link: " << url << "?token=" << operator_token << std::endl;
  });
  dds.stop();
  intake.stop();
  hub.stop();
}

}  // namespace

int main(int argc, char** argv) {
  // glibc gives every thread that allocates while another does an arena of its own, up to
  // eight per core, and what a thread frees stays in its arena: the intake's match and graph,
  // the planner's threads and the encoder each held hundreds of megabytes of freed buffers
  // between scans. Two arenas for two cores: a 30-scan session ends at 265 MB instead of
  // 317-341 MB, the latency within its spread (docs/benchmarks.md).
  if (mallopt(M_ARENA_MAX, 2) != 1) {
    std::cerr << "scanplan-server: could not limit the allocator's arenas; memory may grow\n";
  }
  CLI::App app{"scanplan-server: 3-D mapping workstation for search and rescue"};
  Options options;
  add_options(app, options);
  CLI11_PARSE(app, argc, argv);
  spdlog::set_default_logger(spdlog::stderr_color_mt("server"));
  try {
    run(options);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
