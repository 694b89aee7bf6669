#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan watch --server URL [--token T] [--json] [--top N] [--no-reconnect]`: follows
// GET /api/v1/events over a WebSocket and prints each event on a line (scan progress bars,
// match results, map updates, new plans with their best candidates, mission decisions,
// annotations; map chunks summarised). Reconnects with backoff when the connection drops and
// says so. Ctrl-C ends it cleanly.
void add_watch_command(CLI::App& app);

}  // namespace scanplan::cli
