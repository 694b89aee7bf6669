#pragma once

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

namespace scanplan::cli {

// Prints what `scanplan watch` receives, one line per event with the local time:
// "07:41:02  match_done      scan 2: ndt-icp converged, ...". Scan progress is a bar; on a
// terminal it is redrawn in place, elsewhere (a pipe, a log file) printed at every 10 % so a
// scan does not fill the log with a hundred lines. With json, each event is instead printed as
// the server sent it, one JSON object a line, binary map chunks as a summary object.
class EventPrinter {
 public:
  struct Options {
    bool json = false;
    bool terminal = false;  // whether `out` is a terminal (redraws allowed)
    int top = 3;            // candidates listed after plan_done
  };
  // After plan_done the printer lists the top candidates from fetch_candidates() (the answer of
  // GET /api/v1/candidates); what it throws is shown as a note.
  EventPrinter(std::ostream& out, std::ostream& notes, Options options,
               std::function<nlohmann::json()> fetch_candidates);

  void text_frame(const std::string& payload);
  void binary_frame(const std::string& payload);
  // The client's own news about the connection ("connected", "lost", "retrying", "closed"):
  // always as text on `notes`, and in json mode also as {"type":"connection",...} on `out`.
  void connection(const std::string& state, const std::string& message);

 private:
  void line(const std::string& clock, const std::string& type, const std::string& text);
  void end_progress_line();
  void progress(const std::string& clock, const nlohmann::json& event);
  void plan_summary(const nlohmann::json& event);

  std::ostream& out_;
  std::ostream& notes_;
  Options options_;
  std::function<nlohmann::json()> fetch_candidates_;
  bool progress_open_ = false;               // a bar is drawn without its newline yet
  std::map<std::string, int> printed_step_;  // robot + command -> last 10 % step printed
};

}  // namespace scanplan::cli
