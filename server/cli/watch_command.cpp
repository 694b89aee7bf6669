#include "watch_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "event_printer.hpp"
#include "interrupt_signals.hpp"
#include "operator_client.hpp"
#include "operator_error.hpp"
#include "server_url.hpp"
#include "text_format.hpp"
#include "websocket_client.hpp"

namespace scanplan::cli {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

struct WatchArgs {
  OperatorOptions o;
  int top = 3;
  bool no_reconnect = false;
  double max_backoff_s = 10;
  double idle_timeout_s = 45;
};

std::string seconds_text(Clock::duration d) {
  return fixed(std::chrono::duration<double>(d).count(), d < 10s ? 1 : 0) + " s";
}

// Sleeps up to `d` in short steps so that Ctrl-C is seen at once.
void pause(Clock::duration d, const InterruptSignals& interrupt) {
  const auto until = Clock::now() + d;
  while (!interrupt.raised() && Clock::now() < until) {
    std::this_thread::sleep_for(std::min<Clock::duration>(100ms, until - Clock::now()));
  }
}

std::string close_text(const http::WebSocketMessage& m) {
  std::string s = "the server closed the connection (" + std::to_string(m.close_code);
  if (!m.payload.empty()) s += " " + m.payload;
  return s + ")";
}

// Reads messages until the connection ends or Ctrl-C; returns why it ended, empty for Ctrl-C.
std::string follow(WebSocketClient& ws, EventPrinter& printer, const InterruptSignals& interrupt,
                   Clock::duration idle_limit) {
  try {
    while (!interrupt.raised()) {
      const auto m = ws.receive(250ms);
      if (!m) {
        // The server pings every 20 s: silence well past that is a dead link that TCP may not
        // report for many minutes.
        if (Clock::now() - ws.last_heard() > idle_limit) {
          ws.close(http::websocket_close::kNormal, "no data", 0ms);
          return "no data from the server for " + seconds_text(idle_limit) +
                 " (it pings every 20 s): the link is down";
        }
        continue;
      }
      switch (m->opcode) {
        case http::WebSocketOpcode::kText:
          printer.text_frame(m->payload);
          break;
        case http::WebSocketOpcode::kBinary:
          printer.binary_frame(m->payload);
          break;
        case http::WebSocketOpcode::kClose:
          return close_text(*m);
        default:
          break;
      }
    }
  } catch (const HttpClientError& e) {
    return e.what();
  }
  return {};
}

void run_watch(const WatchArgs& a) {
  // Also checks the token and the URL before anything else. Listing candidates after plan_done
  // must not hold the event stream up for long, hence its shorter timeout.
  OperatorOptions fetch_options = a.o;
  fetch_options.timeout_s = std::min(a.o.timeout_s, 10.0);
  const OperatorClient fetcher(fetch_options);
  const ServerUrl url = parse_server_url(a.o.server);
  const InterruptSignals interrupt;
  EventPrinter printer(
      std::cout, std::cerr, {a.o.json, isatty(STDOUT_FILENO) == 1, a.top},
      [&fetcher] { return fetcher.get_json("/api/v1/candidates", "list the candidates"); });
  const std::map<std::string, std::string> headers{{"Authorization", "Bearer " + a.o.token}};
  const auto max_backoff =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(a.max_backoff_s));
  const auto idle_limit =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(a.idle_timeout_s));
  const std::string action = "watch the events";

  bool ever_connected = false;
  std::optional<Clock::time_point> lost_at;
  Clock::duration backoff = 500ms;
  while (!interrupt.raised()) {
    std::optional<WebSocketClient> ws;
    std::string failure;
    try {
      ws.emplace(WebSocketClient::connect(url, "/api/v1/events", headers, a.o.timeout()));
    } catch (const WebSocketRefusedError& e) {
      if (interrupt.raised()) break;
      OperatorError err = error_for_status(e.status(), e.body(), action, url.base);
      // A refused token will not be accepted on a retry; a busy server (503) may be.
      if (!ever_connected || e.status() < 500) throw err;
      failure = err.what();
    } catch (const HttpClientError& e) {
      if (interrupt.raised()) break;  // Ctrl-C interrupted the attempt
      if (!ever_connected) throw error_for_transport(e);
      failure = e.what();
    }
    if (ws) {
      if (!ever_connected) {
        printer.connection("connected", "watching " + url.base + "/api/v1/events (Ctrl-C ends)");
      } else {
        std::string catch_up;
        try {
          const json s = fetcher.get_json("/api/v1/session", "read the session");
          catch_up = "; the session now has " + s.at("scans").dump() +
                     " scans (scanplan status and candidates show the rest)";
        } catch (const std::exception&) {
          // The catch-up figure is a courtesy; the event stream is what matters.
        }
        printer.connection("connected", "reconnected to " + url.base + " after " +
                                            seconds_text(Clock::now() - *lost_at) +
                                            "; events in between were missed" + catch_up);
      }
      ever_connected = true;
      lost_at.reset();
      backoff = 500ms;
      const std::string why = follow(*ws, printer, interrupt, idle_limit);
      if (why.empty()) {  // Ctrl-C
        ws->close(http::websocket_close::kNormal, "scanplan watch ended", 1s);
        break;
      }
      lost_at = Clock::now();
      if (a.no_reconnect) {
        printer.connection("lost", why);
        throw OperatorError(ExitCode::kUnreachable, "connection lost: " + why);
      }
      printer.connection("lost", why + "; reconnecting");
      continue;  // the first retry at once: a restarting server is often back within a second
    }
    printer.connection("retrying", failure + "; retrying in " + seconds_text(backoff));
    pause(backoff, interrupt);
    backoff = std::min(backoff * 2, max_backoff);
  }
  printer.connection("closed", "watch ended");
}

}  // namespace

void add_watch_command(CLI::App& app) {
  auto a = std::make_shared<WatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "watch", "terminal operator: live events (scan progress, matches, map, plans, decisions)");
  add_operator_options(cmd, a->o,
                       "print each event as one JSON line as the server sent it (map chunks as "
                       "{\"type\":\"map_chunk\",\"scan\",\"bytes\"}, the connection's own news as "
                       "{\"type\":\"connection\",\"state\"})");
  cmd->add_option("--top", a->top, "candidates listed after each new plan")
      ->check(CLI::Range(0, 50))
      ->capture_default_str();
  cmd->add_flag("--no-reconnect", a->no_reconnect,
                "exit (code 2) when the connection drops instead of reconnecting");
  cmd->add_option("--max-backoff", a->max_backoff_s, "longest wait between reconnect attempts, s")
      ->check(CLI::Range(0.5, 600.0))
      ->capture_default_str();
  cmd->add_option("--idle-timeout", a->idle_timeout_s,
                  "seconds of silence (the server pings every 20 s) after which the link counts "
                  "as down")
      ->check(CLI::Range(5.0, 3600.0))
      ->capture_default_str();
  cmd->callback([a] { run_operator_command("watch", [&] { run_watch(*a); }); });
}

}  // namespace scanplan::cli
