#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <functional>
#include <string>

namespace scanplan::cli {

// What every terminal-operator command takes: where the server is, the token, and whether to
// print the server's JSON instead of text.
struct OperatorOptions {
  std::string server = "http://127.0.0.1:8080";
  std::string token;
  bool json = false;
  double timeout_s = 30;

  std::chrono::milliseconds timeout() const {
    return std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  }
};

// --server URL ($SCANPLAN_SERVER), --token T ($SCANPLAN_TOKEN, as for replay), --json,
// --timeout S, and the exit codes in the help footer.
void add_operator_options(CLI::App* cmd, OperatorOptions& options, const std::string& json_help);

// Runs a command's body. An OperatorError (or any other error) becomes one line on stderr,
// "scanplan NAME: message", and CLI::RuntimeError with the exit code (main() returns it).
void run_operator_command(const std::string& name, const std::function<void()>& body);

}  // namespace scanplan::cli
