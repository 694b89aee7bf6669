#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace scanplan::server {

// Which robots' bridges are alive, worked out from what DDS says about the bridges' writers.
// DDS knows writers (publication handles) and the participants they belong to; only the
// bridge's RobotStatus says which robot a participant speaks for. So: every writer is filed
// under its participant, a status sample names the participant's robot, and a robot is
// connected while at least one participant speaking for it is. A participant is lost as soon as
// one of its writers stops being alive (all of a bridge's writers share one AUTOMATIC lease,
// so a killed bridge loses them all at once) and is back when its status writer is alive again:
// the status goes out every second, while a scan writer only revives with the next scan.
//
// Plain handles and no DDS calls here, so the bookkeeping is testable without a network; not
// thread-safe (the owner locks).
class BridgeLiveness {
 public:
  using Handle = std::uint64_t;

  enum class Cause {
    kLeaseExpired,  // no sign of life within the lease: killed, hung or cut off
    kLeft,          // the bridge said goodbye, or its writer was deleted
  };

  struct Change {
    std::string robot;
    bool connected = false;  // false: the robot was lost; true: it is back
    std::string reason;      // why it was lost; empty when back
  };

  // Writer `writer` of participant `participant` is alive: newly matched or alive again.
  std::optional<Change> writer_alive(Handle writer, Handle participant);
  // Writer `writer` is no longer alive. kLeft also forgets it (DDS will not mention it again).
  std::optional<Change> writer_lost(Handle writer, Cause cause);
  // A RobotStatus sample from `writer` (of `participant`) names `robot`. A participant already
  // lost stays lost: a sample received before the lease ran out proves nothing about now.
  std::optional<Change> announced(Handle writer, Handle participant, const std::string& robot);
  // The bridge behind `writer` said goodbye (status "offline"): lost as kLeft, now, rather than
  // when DDS notices its writers go (which looks the same as a kill).
  std::optional<Change> said_goodbye(Handle writer);

  // False for a robot whose every bridge is lost, true for one never seen (nothing says it is
  // gone, and a bridge may still be introducing itself).
  bool connected(const std::string& robot) const;
  // Robots that were seen and are connected now.
  std::vector<std::string> connected_robots() const;
  // Whether samples from `writer` come from a bridge the server has given up on.
  bool writer_from_lost_participant(Handle writer) const;
  bool participant_lost(Handle participant) const;
  bool knows_writer(Handle writer) const { return writers_.count(writer) > 0; }

  // Why `cause` ended a bridge, in the operator's words.
  static std::string reason(Cause cause);

 private:
  struct Writer {
    Handle participant = 0;
    bool alive = true;
  };
  struct Participant {
    std::string robot;  // empty until its first status
    std::optional<Handle> status_writer;
    bool lost = false;
    std::string reason;
  };

  // Re-evaluates `robot` after a change; an event when its connected state flipped (none on
  // the first sight of a robot: there was nothing to come back from).
  std::optional<Change> update(const std::string& robot, const std::string& reason);
  bool any_participant_connected(const std::string& robot) const;
  void mark_lost(Participant& participant, Handle participant_handle, Cause cause);

  std::map<Handle, Writer> writers_;
  std::map<Handle, Participant> participants_;
  std::map<std::string, bool> robots_;  // every robot seen: connected as last reported
};

}  // namespace scanplan::server
