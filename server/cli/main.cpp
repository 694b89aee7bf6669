// scanplan: the command-line tool (DESIGN.md "CLI"). JSON results on stdout; human text and
// progress on stderr.
#include <CLI/CLI.hpp>

#include <iostream>

#include "area_command.hpp"
#include "candidates_command.hpp"
#include "decision_command.hpp"
#include "export_command.hpp"
#include "operator_actions.hpp"
#include "register_command.hpp"
#include "replay_command.hpp"
#include "scan_command.hpp"
#include "simulate_command.hpp"
#include "status_command.hpp"
#include "watch_command.hpp"

int main(int argc, char** argv) {
  CLI::App app{"scanplan: offline tools and terminal operator for the scanplan workstation"};
  app.require_subcommand(1);
  scanplan::cli::add_scan_command(app);
  scanplan::cli::add_register_command(app);
  scanplan::cli::add_replay_command(app);
  scanplan::cli::add_simulate_command(app);
  // The terminal operator: a client of a running scanplan-server's REST and WebSocket API.
  scanplan::cli::add_status_command(app);
  scanplan::cli::add_candidates_command(app);
  scanplan::cli::add_area_command(app);
  scanplan::cli::add_export_command(app);
  scanplan::cli::add_operator_actions(app);
  scanplan::cli::add_decision_commands(app);
  scanplan::cli::add_watch_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "scanplan: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
