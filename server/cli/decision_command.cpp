#include "decision_command.hpp"

#include <unistd.h>

#include <iostream>
#include <memory>
#include <string>

#include "candidate_table.hpp"
#include "event_text.hpp"
#include "operator_client.hpp"
#include "operator_error.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

struct DecisionArgs {
  OperatorOptions o;
  std::uint64_t id = 0;
  std::string by, reason;
  bool yes = false;
};

// Shows the candidate and asks; true to go on. A candidate missing from the plan is not asked
// about: the server's 404 then says so in its own words.
bool confirm(const OperatorClient& client, const std::string& action, const DecisionArgs& a) {
  const json answer = client.get_json("/api/v1/candidates", "list the candidates");
  for (const json& c : answer.at("candidates")) {
    if (c.at("id").get<std::uint64_t>() != a.id) continue;
    std::cerr << describe_candidate(c) << "\n";
    if (action == "approve") {
      std::cerr << "Approve: robot " << answer.at("plan").at("robot").get<std::string>()
                << " drives there now and scans on arrival. Go? [y/N] " << std::flush;
    } else {
      std::cerr << "Reject candidate " << a.id << "? [y/N] " << std::flush;
    }
    std::string reply;
    if (!std::getline(std::cin, reply)) return false;
    return reply == "y" || reply == "Y" || reply == "yes" || reply == "YES" || reply == "Yes";
  }
  return true;
}

void run_decision(const std::string& action, const DecisionArgs& a) {
  const OperatorClient client(a.o);
  const std::string what = action + " candidate " + std::to_string(a.id);
  if (!a.yes && isatty(STDIN_FILENO) && !confirm(client, action, a)) {
    throw OperatorError(
        ExitCode::kDeclined,
        "not " + std::string(action == "approve" ? "approved" : "rejected") + ": nothing was sent");
  }
  json body = json::object();
  if (!a.by.empty()) body["by"] = a.by;
  if (!a.reason.empty()) body["reason"] = a.reason;
  const std::string answer =
      client.post("/api/v1/candidates/" + std::to_string(a.id) + "/" + action,
                  body.empty() ? json() : body, what);
  if (a.o.json) {
    std::cout << json::parse(answer, nullptr, false).dump() << std::endl;
    return;
  }
  // The answer has the fields of the mission event the server broadcasts for the decision.
  json event = json::parse(answer, nullptr, false);
  if (!event.is_object()) event = json::object();
  event["type"] = "mission";
  event["kind"] = action;
  std::cout << describe_event(event) << std::endl;
}

void add_one(CLI::App& app, const std::string& action, const std::string& help) {
  auto a = std::make_shared<DecisionArgs>();
  CLI::App* cmd = app.add_subcommand(action, help);
  cmd->add_option("id", a->id, "the candidate's id (the id column of `scanplan candidates`)")
      ->required()
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            if (!v.empty() && v.find_first_not_of("0123456789") == std::string::npos &&
                v.find_first_not_of('0') != std::string::npos) {
              return {};
            }
            return "a candidate id is a positive whole number (the id column of `scanplan "
                   "candidates`), got '" +
                   v + "'";
          },
          "ID", "candidate id"));
  add_operator_options(cmd, a->o, "print the server's answer as JSON");
  cmd->add_option("--by", a->by, "who decides, recorded in the session (\"operator NAME\")");
  if (action == "reject") cmd->add_option("--reason", a->reason, "why, recorded in the session");
  cmd->add_flag("--yes,-y", a->yes, "do not ask for confirmation on a terminal");
  cmd->callback([a, action] { run_operator_command(action, [&] { run_decision(action, *a); }); });
}

}  // namespace

void add_decision_commands(CLI::App& app) {
  add_one(app, "approve",
          "terminal operator: send the robot to a candidate (operator token), then it scans");
  add_one(app, "reject", "terminal operator: reject a candidate (operator token)");
}

}  // namespace scanplan::cli
