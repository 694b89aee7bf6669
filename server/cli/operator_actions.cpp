#include "operator_actions.hpp"

#include <iostream>
#include <memory>
#include <string>

#include "candidate_table.hpp"
#include "operator_client.hpp"
#include "operator_error.hpp"
#include "text_format.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

json parsed(const std::string& answer) {
  json j = json::parse(answer, nullptr, false);
  if (!j.is_object()) throw OperatorError(ExitCode::kFailure, "the server's answer is not JSON");
  return j;
}

struct ProposeArgs {
  OperatorOptions o;
  double x = 0, y = 0;
  std::string robot, by;
};

void run_propose(const ProposeArgs& a) {
  const OperatorClient client(a.o);
  json body = {{"x", a.x}, {"y", a.y}};
  if (!a.robot.empty()) body["robot"] = a.robot;
  if (!a.by.empty()) body["by"] = a.by;
  const json c = parsed(client.post("/api/v1/goals", body, "propose a scan point"));
  if (a.o.json) {
    std::cout << c.dump() << std::endl;
    return;
  }
  std::cout << describe_candidate(c) << "\n"
            << "proposed for " << c.value("robot", std::string("the robot"))
            << "; send it there with: scanplan approve " << c.value("id", std::uint64_t{0})
            << std::endl;
}

struct AnnotateArgs {
  OperatorOptions o;
  std::string kind;
  double x = 0, y = 0, z = 0;
  std::string text, by;
};

void run_annotate(const AnnotateArgs& a) {
  const OperatorClient client(a.o);
  json body = {{"kind", a.kind}, {"x", a.x}, {"y", a.y}, {"z", a.z}};
  if (!a.text.empty()) body["text"] = a.text;
  if (!a.by.empty()) body["by"] = a.by;
  const json m = parsed(client.post("/api/v1/annotations", body, "mark a " + a.kind));
  if (a.o.json) {
    std::cout << m.dump() << std::endl;
    return;
  }
  std::cout << m.value("kind", a.kind) << " #" << m.value("id", std::int64_t{0}) << " at "
            << position(m.value("x", a.x), m.value("y", a.y)) << ", z "
            << fixed(m.value("z", a.z), 1) << " m by " << m.value("author", std::string("?"))
            << (a.text.empty() ? "" : ": " + a.text) << std::endl;
}

struct ExcludeArgs {
  OperatorOptions o;
  std::int64_t id = 0;
  std::string reason, by;
  bool restore = false;
};

void run_exclude(const ExcludeArgs& a) {
  const OperatorClient client(a.o);
  json body = json::object();
  if (!a.reason.empty()) body["reason"] = a.reason;
  if (!a.by.empty()) body["by"] = a.by;
  const std::string path = "/api/v1/scans/" + std::to_string(a.id);
  const json s = parsed(a.restore ? client.post(path + "/restore", body, "put scan back")
                                  : client.del(path, body, "take scan out of the map"));
  if (a.o.json) {
    std::cout << s.dump() << std::endl;
    return;
  }
  std::cout << "scan " << a.id
            << (a.restore ? " is back in the map"
                          : " is out of the map (its file stays; "
                            "--restore puts it back)")
            << std::endl;
}

}  // namespace

void add_operator_actions(CLI::App& app) {
  auto p = std::make_shared<ProposeArgs>();
  CLI::App* propose = app.add_subcommand(
      "propose",
      "terminal operator: propose your own scan point (map frame, metres); the server "
      "checks the robot can get there and adds it to the plan to approve");
  propose->add_option("x", p->x, "x (m)")->required();
  propose->add_option("y", p->y, "y (m)")->required();
  propose->add_option("--robot", p->robot,
                      "for this robot (default: the one whose scan came last)");
  propose->add_option("--by", p->by, "who proposes, recorded in the session");
  add_operator_options(propose, p->o, "print the new candidate as the server sent it");
  propose->callback([p] { run_operator_command("propose", [&] { run_propose(*p); }); });

  auto n = std::make_shared<AnnotateArgs>();
  CLI::App* annotate = app.add_subcommand(
      "annotate", "terminal operator: mark a victim, hazard, blockage or note on the map");
  annotate->add_option("kind", n->kind, "victim, hazard, blocked or note")
      ->required()
      ->check(CLI::IsMember({"victim", "hazard", "blocked", "note"}));
  annotate->add_option("x", n->x, "x (m, map frame)")->required();
  annotate->add_option("y", n->y, "y (m, map frame)")->required();
  annotate->add_option("--z", n->z, "height (m)")->capture_default_str();
  annotate->add_option("--text", n->text, "what is there (required for a note)");
  annotate->add_option("--by", n->by, "who marks it");
  add_operator_options(annotate, n->o, "print the stored annotation as the server sent it");
  annotate->callback([n] { run_operator_command("annotate", [&] { run_annotate(*n); }); });

  auto e = std::make_shared<ExcludeArgs>();
  CLI::App* exclude = app.add_subcommand(
      "exclude-scan",
      "terminal operator: take a scan out of the map (a bad one), or put it back "
      "with --restore; recorded with who and why");
  exclude->add_option("id", e->id, "the scan's id (scanplan status)")
      ->required()
      ->check(CLI::PositiveNumber);
  exclude->add_option("--reason", e->reason, "why, recorded in the session");
  exclude->add_option("--by", e->by, "who decides");
  exclude->add_flag("--restore", e->restore, "put the scan back into the map");
  add_operator_options(exclude, e->o, "print the scan as the server sent it");
  exclude->callback([e] { run_operator_command("exclude-scan", [&] { run_exclude(*e); }); });
}

}  // namespace scanplan::cli
