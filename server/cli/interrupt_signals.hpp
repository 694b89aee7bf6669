#pragma once

namespace scanplan::cli {

// Ctrl-C (SIGINT) and SIGTERM as a flag that a long-running command polls, so it can end
// cleanly (close its WebSocket, finish its line). The handlers interrupt blocking calls
// (no SA_RESTART); after the first signal the default action is restored, so a second Ctrl-C
// ends the process at once if the clean ending hangs.
class InterruptSignals {
 public:
  InterruptSignals();
  ~InterruptSignals();
  InterruptSignals(const InterruptSignals&) = delete;
  InterruptSignals& operator=(const InterruptSignals&) = delete;

  bool raised() const;
  int signal() const;  // the signal received, 0 if none
};

}  // namespace scanplan::cli
