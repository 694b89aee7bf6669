#include "dds/bridge_liveness.hpp"

#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::server {

std::string BridgeLiveness::reason(Cause cause) {
  switch (cause) {
    case Cause::kLeaseExpired:
      // A bridge stopped without its goodbye looks the same to DDS.
      return "no sign of life from the bridge for " +
             std::to_string(dds::kBridgeLivelinessLease.count()) +
             " ms (its DDS liveliness lease expired): it was killed, hangs or lost its link";
    case Cause::kLeft:
      return "the bridge shut down";
  }
  return "the bridge was lost";
}

bool BridgeLiveness::any_participant_connected(const std::string& robot) const {
  for (const auto& [handle, p] : participants_) {
    if (p.robot == robot && !p.lost) return true;
  }
  return false;
}

std::optional<BridgeLiveness::Change> BridgeLiveness::update(const std::string& robot,
                                                             const std::string& reason) {
  if (robot.empty()) return std::nullopt;
  const bool now = any_participant_connected(robot);
  const auto [it, first] = robots_.try_emplace(robot, now);
  if (first || it->second == now) return std::nullopt;
  it->second = now;
  return Change{robot, now, now ? std::string() : reason};
}

void BridgeLiveness::mark_lost(Participant& p, Handle participant, Cause cause) {
  p.lost = true;
  p.reason = reason(cause);
  // DDS reports each writer on its own, one after the other; the bridge is gone with the first.
  // Until DDS says a writer is alive again, none of its samples count.
  for (auto& [handle, w] : writers_) {
    if (w.participant == participant) w.alive = false;
  }
}

std::optional<BridgeLiveness::Change> BridgeLiveness::writer_alive(Handle writer,
                                                                   Handle participant) {
  const auto it = writers_.try_emplace(writer, Writer{participant, true}).first;
  it->second.alive = true;
  Participant& p = participants_[it->second.participant];
  if (!p.lost || p.status_writer != writer) return std::nullopt;
  // The status writer speaks again (DDS revives a writer only when data from it arrives).
  p.lost = false;
  p.reason.clear();
  return update(p.robot, "");
}

std::optional<BridgeLiveness::Change> BridgeLiveness::writer_lost(Handle writer, Cause cause) {
  const auto it = writers_.find(writer);
  if (it == writers_.end()) return std::nullopt;
  const Handle participant = it->second.participant;
  Participant& p = participants_[participant];
  std::optional<Change> change;
  if (!p.lost) {
    mark_lost(p, participant, cause);
    change = update(p.robot, p.reason);
  }
  it->second.alive = false;
  if (cause == Cause::kLeft) {
    writers_.erase(it);
    bool any_left = false;
    for (const auto& [h, w] : writers_) any_left |= w.participant == participant;
    if (!any_left) participants_.erase(participant);
  }
  return change;
}

std::optional<BridgeLiveness::Change> BridgeLiveness::announced(Handle writer, Handle participant,
                                                                const std::string& robot) {
  // The sample may be taken before DDS's "alive" for its writer was handled: the sample itself
  // shows the writer was alive when it wrote.
  const auto it = writers_.try_emplace(writer, Writer{participant, true}).first;
  Participant& p = participants_[it->second.participant];
  p.status_writer = writer;
  // A bridge has one robot id for its whole life (--robot-id), so this only fills it in.
  p.robot = robot;
  // Lost, but DDS has called the writer alive since: a participant lost before its first
  // status is revived here, as writer_alive could not know it was the status writer.
  if (p.lost && it->second.alive) {
    p.lost = false;
    p.reason.clear();
  }
  if (p.lost) return std::nullopt;
  return update(robot, "");
}

std::optional<BridgeLiveness::Change> BridgeLiveness::said_goodbye(Handle writer) {
  const auto it = writers_.find(writer);
  if (it == writers_.end()) return std::nullopt;
  Participant& p = participants_[it->second.participant];
  if (p.lost) return std::nullopt;
  mark_lost(p, it->second.participant, Cause::kLeft);
  return update(p.robot, p.reason);
}

bool BridgeLiveness::connected(const std::string& robot) const {
  const auto it = robots_.find(robot);
  return it == robots_.end() || it->second;
}

std::vector<std::string> BridgeLiveness::connected_robots() const {
  std::vector<std::string> out;
  for (const auto& [robot, connected] : robots_) {
    if (connected) out.push_back(robot);
  }
  return out;
}

bool BridgeLiveness::writer_from_lost_participant(Handle writer) const {
  const auto it = writers_.find(writer);
  if (it == writers_.end()) return false;
  return participant_lost(it->second.participant);
}

bool BridgeLiveness::participant_lost(Handle participant) const {
  const auto it = participants_.find(participant);
  return it != participants_.end() && it->second.lost;
}

}  // namespace scanplan::server
