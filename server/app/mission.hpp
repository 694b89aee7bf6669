#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/events.hpp"
#include "app/live_map.hpp"
#include "app/plan_book.hpp"
#include "app/robot_board.hpp"
#include "app/robot_link.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// Why a decision cannot be carried out; the REST layer maps each to an HTTP status.
enum class MissionErrc {
  kNotFound,      // no such candidate in the current plans
  kConflict,      // the candidate or the robot is not in a state that allows it
  kNoRobot,       // no robot can take the command (its bridge is gone)
  kNoMap,         // nothing to decide on before the first scan
  kUnknownRobot,  // a robot that has sent no scan
  kGoalRefused,   // the operator's own goal is not a place the robot can be sent to
};

class MissionError : public std::runtime_error {
 public:
  MissionError(MissionErrc errc_, std::string code_, const std::string& message)
      : std::runtime_error(message), errc(errc_), code(std::move(code_)) {}
  MissionErrc errc;
  std::string code;  // the machine-readable reason (docs/api.md), e.g. "not_movable"
};

struct Approval {
  std::uint64_t candidate = 0;
  std::string robot;
  std::uint32_t command_id = 0;
  double x = 0, y = 0, yaw_deg = 0;  // where the robot was sent, facing which way
  std::string by;
};

struct Rejection {
  std::uint64_t candidate = 0;
  std::string by;
  std::string reason;
};

struct Cancellation {
  std::uint64_t candidate = 0;
  std::string robot;
  std::string by;
};

// The operator's own scan point, added to a robot's plan.
struct Proposal {
  CandidateRecord candidate;
  std::string robot;
  std::uint64_t plan = 0;  // the plan it was added to
};

// The operator's decisions and what follows from them: nothing moves without an approval.
// Approving a candidate sends its robot there; when the robot reports arrival, the scan command
// follows. Every decision is recorded in the session with who made it and when. Decisions that
// cannot be carried out throw MissionError.
class Mission {
 public:
  Mission(LiveMap& map, PlanBook& plans, const RobotBoard& robots, RobotLink& link,
          SessionStore& session, const Events& events);

  Approval approve(std::uint64_t candidate, const std::string& by);
  Rejection reject(std::uint64_t candidate, const std::string& by, const std::string& reason);
  // Stops an approved move where the robot now is.
  Cancellation cancel(std::uint64_t candidate, const std::string& by);
  // The operator's own scan point: added to `robot`'s plan (empty: the robot whose scan came
  // last) as a custom candidate (to be approved like the planner's), recorded as "goal".
  Proposal propose(double x, double y, const std::string& robot, const std::string& by);
  // The newest `limit` recorded decisions, oldest first.
  std::vector<SessionEvent> log(std::size_t limit) const;
  // The operator's parameters (PUT /api/v1/params): applied (the plans are made anew), kept in
  // the session for a restart, recorded as "params" and announced to every page.
  MissionParams set_params(const MissionParams& params, const std::string& by);
  // The operator ends the mission (nothing more is worth scanning, or the crew must leave), or
  // takes it up again: recorded as "finish" / "resume"; a restarted server knows (the log).
  void finish(const std::string& by, const std::string& reason);
  void resume(const std::string& by);
  // Who finished it and when, while it stands.
  std::optional<std::pair<std::string, std::string>> finished() const;

  // From the robots' side (the DDS thread).
  void on_status(const std::string& robot, const RobotStatus& status);
  // The robot's bridge is gone: tells the operator, records it, reports the scan it cost and
  // frees an approved move so the operator can decide again.
  void on_robot_lost(const RobotLoss& loss);
  void on_robot_back(const std::string& robot);

 private:
  std::optional<std::pair<std::string, std::string>> finished_;  // by, at
  struct ActiveMove {
    std::uint32_t command_id;
    std::uint64_t candidate;
  };
  PlanBook::Found find(std::uint64_t candidate) const;
  // Throws unless the candidate is still open to a decision.
  static void require_open(const PlanBook::Found& found, std::uint64_t id);
  // Throws when another robot is already going within the claim separation of `c`.
  void require_apart(const CandidateRecord& c) const;
  // Publishes a "mission" event {kind, ...} and records it in the session.
  void record(const std::string& kind, nlohmann::json details);
  // Publishes an event of its own type and records it in the session under that name.
  void record_event(const std::string& type, const nlohmann::json& details);

  LiveMap& map_;
  PlanBook& plans_;
  const RobotBoard& robots_;
  RobotLink& link_;
  SessionStore& session_;
  const Events& events_;
  mutable std::mutex mutex_;
  std::map<std::string, ActiveMove> moving_;  // by robot
};

}  // namespace scanplan::server
