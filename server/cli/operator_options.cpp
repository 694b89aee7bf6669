#include "operator_options.hpp"

#include <iostream>
#include <nlohmann/json.hpp>

#include "exit_codes.hpp"
#include "operator_error.hpp"

namespace scanplan::cli {

void add_operator_options(CLI::App* cmd, OperatorOptions& o, const std::string& json_help) {
  cmd->add_option("--server", o.server, "scanplan-server's URL ($SCANPLAN_SERVER)")
      ->envname("SCANPLAN_SERVER")
      ->capture_default_str();
  cmd->add_option("--token", o.token,
                  "operator or viewer token ($SCANPLAN_TOKEN); approve and reject need the "
                  "operator's")
      ->envname("SCANPLAN_TOKEN");
  cmd->add_flag("--json", o.json, json_help);
  cmd->add_option("--timeout", o.timeout_s, "seconds to wait for the server on each request")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  cmd->footer(exit_code_help());
}

void run_operator_command(const std::string& name, const std::function<void()>& body) {
  ExitCode code = ExitCode::kOk;
  try {
    body();
  } catch (const OperatorError& e) {
    std::cerr << "scanplan " << name << ": " << e.what() << std::endl;
    code = e.code();
  } catch (const nlohmann::json::exception& e) {
    // The server answered, but not as docs/api.md says: a version mismatch more than anything.
    std::cerr << "scanplan " << name << ": the server's answer is not as documented (" << e.what()
              << "); are scanplan and scanplan-server the same version?" << std::endl;
    code = ExitCode::kFailure;
  } catch (const HttpClientError& e) {
    const OperatorError mapped = error_for_transport(e);
    std::cerr << "scanplan " << name << ": " << mapped.what() << std::endl;
    code = mapped.code();
  } catch (const std::exception& e) {
    std::cerr << "scanplan " << name << ": " << e.what() << std::endl;
    code = ExitCode::kFailure;
  }
  if (code != ExitCode::kOk) throw CLI::RuntimeError(to_int(code));
}

}  // namespace scanplan::cli
