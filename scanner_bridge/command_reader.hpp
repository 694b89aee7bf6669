#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::bridge {

struct ScanRequest {
  std::uint32_t command_id;
};
struct MoveRequest {
  std::uint32_t command_id;
  double x, y, yaw_deg;
};
using Command = std::variant<ScanRequest, MoveRequest>;

// Receives the commands addressed to one robot (or to every robot: an empty robot_id), in the
// order the server sent them across both command topics.
class CommandReader {
 public:
  CommandReader(dds::Participant& participant, std::string robot_id);
  // Waits up to `timeout` for commands; returns those that arrived, oldest first.
  std::vector<Command> wait(std::chrono::milliseconds timeout);

 private:
  std::string robot_id_;
  dds_entity_t scan_reader_, move_reader_;
  std::unique_ptr<dds::ReadWaiter> waiter_;
};

}  // namespace scanplan::bridge
