#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "dds_link.hpp"
#include "events.hpp"
#include "scan_store.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// Thrown for a decision that cannot be carried out; the API turns it into a JSON error.
class MissionError : public std::runtime_error {
 public:
  MissionError(int status, std::string code, const std::string& message)
      : std::runtime_error(message), status(status), code(std::move(code)) {}
  int status;
  std::string code;
};

// The operator's decisions and what follows from them: nothing moves without an approval.
// Approving a candidate sends its robot there over DDS; when the robot reports arrival, the
// scan command follows. Every decision is recorded in the session with who made it and when.
class Mission {
 public:
  Mission(ScanStore& store, DdsLink& dds, SessionStore& session, const Events& events);

  nlohmann::json approve(std::uint64_t candidate, const std::string& by);
  nlohmann::json reject(std::uint64_t candidate, const std::string& by, const std::string& reason);
  // Stops an approved move where the robot now is.
  nlohmann::json cancel(std::uint64_t candidate, const std::string& by);
  // The operator's own scan point: added to `robot`'s plan (empty: the robot whose scan came
  // last) as a custom candidate (to be approved like the planner's), recorded as "goal".
  // Throws MissionError 400 naming why the robot cannot go there, 409 before the first plan.
  struct Proposed {
    CandidateRecord candidate;
    std::string robot;
    std::uint64_t plan = 0;  // the plan it was added to
  };
  Proposed propose(double x, double y, const std::string& robot, const std::string& by);
  // The newest `limit` recorded decisions, oldest first: {"id","at","kind",...details}.
  nlohmann::json log(std::size_t limit) const;
  // From the DDS thread.
  void on_status(const std::string& robot, const RobotStatus& status);
  // The robot's bridge is gone: tells the operator, records it, reports the scan it cost and
  // frees an approved move so the operator can decide again.
  void on_robot_lost(const RobotLoss& loss);
  void on_robot_back(const std::string& robot);

 private:
  struct ActiveMove {
    std::uint32_t command_id;
    std::uint64_t candidate;
  };
  CandidateRecord find(std::uint64_t candidate, std::string* robot) const;
  // Publishes a "mission" event {kind, ...} and records it in the session.
  void record(const std::string& kind, nlohmann::json details);
  // Publishes an event of its own type and records it in the session under that name.
  void record_event(const std::string& type, const nlohmann::json& details);

  ScanStore& store_;
  DdsLink& dds_;
  SessionStore& session_;
  const Events& events_;
  std::mutex mutex_;
  std::map<std::string, ActiveMove> moving_;  // by robot
};

}  // namespace scanplan::server
