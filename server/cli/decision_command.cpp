#include "decision_command.hpp"

#include <unistd.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "candidate_table.hpp"
#include "event_text.hpp"
#include "operator_client.hpp"
#include "operator_error.hpp"
#include "text_format.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

struct DecisionArgs {
  OperatorOptions o;
  std::uint64_t id = 0;
  std::string by, reason;
  bool yes = false;
  double wait_s = 15;  // approve: how long to wait for the robot's first answer (0: not at all)
};

// The robot's first answer to an approved move, from what the server knows of it: its status
// for the move's command, or the candidate marked refused. Empty while it has not answered.
struct RobotAnswer {
  bool refused = false;
  std::string state, message;
};

std::optional<RobotAnswer> answer_to(const OperatorClient& client, const json& approval,
                                     std::uint64_t id) {
  const std::string robot = approval.value("robot", "");
  const auto command = approval.value("command_id", std::uint64_t{0});
  const json session = client.get_json("/api/v1/session", "read the robots' state");
  if (const auto r = session.find("robots"); r != session.end() && r->contains(robot)) {
    const json& s = (*r)[robot];
    const std::string state = s.value("state", "");
    if (s.value("command_id", std::uint64_t{0}) == command && state != "idle" && !state.empty()) {
      return RobotAnswer{state == "refused", state, s.value("message", "")};
    }
  }
  const json plan = client.get_json("/api/v1/candidates", "list the candidates");
  for (const json& c : plan.value("candidates", json::array())) {
    if (c.value("id", std::uint64_t{0}) != id) continue;
    const std::string state = c.value("state", "");
    if (state == "refused") return RobotAnswer{true, state, c.value("note", "")};
    if (state == "reached") return RobotAnswer{false, "arrived", ""};
  }
  return std::nullopt;
}

// Waits for the robot's first answer to the approval: an approved move the robot then refuses
// is no move, and a script must not go on as if it were.
RobotAnswer wait_for_robot(const OperatorClient& client, const json& approval,
                           const DecisionArgs& a) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long long>(a.wait_s * 1000));
  for (;;) {
    if (auto answer = answer_to(client, approval, a.id)) return *answer;
    if (std::chrono::steady_clock::now() >= deadline) {
      throw OperatorError(ExitCode::kNoAnswer,
                          "approved, but robot " + approval.value("robot", std::string("?")) +
                              " has not answered within " + fixed(a.wait_s, 0) + " s" +
                              ": see `scanplan status` or `scanplan watch`");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

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
  // The answer has the fields of the mission event the server broadcasts for the decision.
  json event = json::parse(answer, nullptr, false);
  if (!event.is_object()) event = json::object();
  if (a.o.json) {
    std::cout << event.dump() << std::endl;
  } else {
    event["type"] = "mission";
    event["kind"] = action;
    std::cout << describe_event(event) << std::endl;
  }
  if (action != "approve" || a.wait_s <= 0) return;
  const RobotAnswer robot = wait_for_robot(client, event, a);
  const std::string who = event.value("robot", std::string("the robot"));
  if (robot.refused) {
    throw OperatorError(ExitCode::kRefusedByRobot,
                        who + " refused to go to candidate " + std::to_string(a.id) +
                            (robot.message.empty() ? "" : ": " + robot.message));
  }
  std::cerr << who << " answered: " << robot.state
            << (robot.message.empty() ? "" : " (" + robot.message + ")") << std::endl;
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
  if (action == "approve") {
    cmd->add_option("--wait", a->wait_s,
                    "seconds to wait for the robot's first answer (moving, or refused: exit 10; "
                    "none: exit 11); 0 does not wait")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 3600.0));
  }
  cmd->callback([a, action] { run_operator_command(action, [&] { run_decision(action, *a); }); });
}

}  // namespace

void add_decision_commands(CLI::App& app) {
  add_one(app, "approve",
          "terminal operator: send the robot to a candidate (operator token), then it scans");
  add_one(app, "reject", "terminal operator: reject a candidate (operator token)");
}

}  // namespace scanplan::cli
