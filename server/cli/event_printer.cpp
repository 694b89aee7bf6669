#include "event_printer.hpp"

#include <chrono>
#include <cmath>
#include <ctime>

#include "candidate_table.hpp"
#include "common/iso_time.hpp"
#include "event_text.hpp"
#include "text_format.hpp"

namespace scanplan::cli {

using nlohmann::json;

namespace {

constexpr const char* kIndent = "          ";  // under the text column: time (8) + 2 spaces

std::string clock_of_event(const json& e) {
  if (const auto at = e.find("at"); at != e.end() && at->is_string()) {
    if (auto c = local_clock_of(at->get<std::string>())) return *c;
  }
  return local_clock_now();
}

// The server's "at" format, for the client's own connection events.
std::string utc_now() {
  return iso8601_utc_now();
}

}  // namespace

EventPrinter::EventPrinter(std::ostream& out, std::ostream& notes, Options options,
                           std::function<json()> fetch_candidates)
    : out_(out), notes_(notes), options_(options), fetch_candidates_(std::move(fetch_candidates)) {}

void EventPrinter::end_progress_line() {
  if (!progress_open_) return;
  out_ << "\n";
  progress_open_ = false;
}

void EventPrinter::line(const std::string& clock, const std::string& type,
                        const std::string& text) {
  end_progress_line();
  std::string t = type;
  if (t.size() < 14) t.resize(14, ' ');
  out_ << clock << "  " << t << "  " << text << std::endl;
}

void EventPrinter::text_frame(const std::string& payload) {
  if (options_.json) {
    out_ << payload << std::endl;
    return;
  }
  const json e = json::parse(payload, nullptr, false);
  if (!e.is_object()) {
    line(local_clock_now(), "unreadable", payload.substr(0, 200));
    return;
  }
  const std::string type = e.value("type", "event");
  if (type == "scan_progress") {
    progress(clock_of_event(e), e);
    return;
  }
  line(clock_of_event(e), type, describe_event(e));
  if (type == "plan_done") plan_summary(e);
}

void EventPrinter::progress(const std::string& clock, const json& e) {
  const std::string state = e.value("state", "");
  std::string text = clock + "  scan_progress   " + describe_event(e);
  if (options_.terminal) {
    // Redraw the bar in place: "\r" back to the line's start, ESC[K clears what was longer.
    out_ << "\r" << text << "\x1b[K";
    progress_open_ = true;
    if (state != "scanning") end_progress_line();
    out_.flush();
    return;
  }
  const std::string key = e.value("robot", "") + "/" + e.value("command_id", json()).dump();
  const double f = e.value("fraction", 0.0);
  const int step = std::isfinite(f) ? static_cast<int>(std::floor(f * 10 + 1e-9)) : 0;
  const auto it = printed_step_.find(key);
  if (state == "scanning" && it != printed_step_.end() && it->second == step) return;
  printed_step_[key] = step;
  out_ << text << std::endl;
  if (state != "scanning") printed_step_.erase(key);
}

void EventPrinter::plan_summary(const json& event) {
  if (!fetch_candidates_ || options_.top <= 0) return;
  try {
    const json answer = fetch_candidates_();
    const json& plan = answer.at("plan");
    if (plan.is_null()) return;
    if (plan.at("id") != event.value("plan", json())) {
      out_ << kIndent << "(plan " << plan.at("id").dump() << " has replaced it since)\n";
    }
    int shown = 0;
    for (const json& c : answer.at("candidates")) {
      if (shown++ == options_.top) break;
      out_ << kIndent << describe_candidate(c) << "\n";
    }
    const std::size_t total = answer.at("candidates").size();
    if (total > static_cast<std::size_t>(options_.top)) {
      out_ << kIndent << "(" << total - static_cast<std::size_t>(options_.top)
           << " more: scanplan candidates)\n";
    }
    out_.flush();
  } catch (const std::exception& e) {
    out_ << kIndent << "(cannot list the candidates: " << e.what() << ")" << std::endl;
  }
}

void EventPrinter::binary_frame(const std::string& payload) {
  const auto chunk = parse_map_chunk(payload);
  if (options_.json) {
    if (chunk) {
      out_ << map_chunk_json(*chunk).dump() << std::endl;
    } else {
      out_ << json{{"type", "binary"}, {"bytes", payload.size()}}.dump() << std::endl;
    }
    return;
  }
  if (!chunk) {
    line(local_clock_now(), "binary", std::to_string(payload.size()) + " bytes (too short)");
    return;
  }
  line(chunk->sent_ns ? local_clock_of_ns(chunk->sent_ns) : local_clock_now(), "map_chunk",
       describe_map_chunk(*chunk));
}

void EventPrinter::connection(const std::string& state, const std::string& message) {
  end_progress_line();
  out_.flush();
  notes_ << local_clock_now() << "  connection      " << message << std::endl;
  if (options_.json) {
    out_ << json{{"type", "connection"}, {"at", utc_now()}, {"state", state}, {"message", message}}
                .dump()
         << std::endl;
  }
}

}  // namespace scanplan::cli
