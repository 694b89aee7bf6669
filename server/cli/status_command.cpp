#include "status_command.hpp"

#include <iostream>
#include <memory>

#include "operator_client.hpp"
#include "status_report.hpp"

namespace scanplan::cli {
namespace {

void run_status(const OperatorOptions& o) {
  const OperatorClient client(o);
  if (o.json) {
    std::string body = client.get_raw("/api/v1/session", "read the session");
    while (!body.empty() && (body.back() == '\n' || body.back() == '\r')) body.pop_back();
    std::cout << body << std::endl;
    return;
  }
  const auto session = client.get_json("/api/v1/session", "read the session");
  const auto scans = client.get_json("/api/v1/scans", "list the scans");
  for (const std::string& line : render_status(client.server(), session, scans)) {
    std::cout << line << "\n";
  }
  std::cout.flush();
}

}  // namespace

void add_status_command(CLI::App& app) {
  auto o = std::make_shared<OperatorOptions>();
  CLI::App* cmd = app.add_subcommand(
      "status", "terminal operator: the session's scans, areas, robots and current scan");
  add_operator_options(cmd, *o, "print the server's GET /api/v1/session answer as it came");
  cmd->callback([o] { run_operator_command("status", [&] { run_status(*o); }); });
}

}  // namespace scanplan::cli
