#include "command_reader.hpp"

#include <algorithm>

#include "scanplan.h"
#include "scanplan/msgs/topics.hpp"

namespace scanplan::bridge {

CommandReader::CommandReader(dds::Participant& p, std::string robot_id)
    : robot_id_(std::move(robot_id)) {
  scan_reader_ = p.reader(scanplan_ScanCommand_desc, topics::kScanCommand, dds::QosKind::kCommand);
  move_reader_ = p.reader(scanplan_MoveCommand_desc, topics::kMoveCommand, dds::QosKind::kCommand);
  waiter_ = std::make_unique<dds::ReadWaiter>(p.handle(),
                                              std::initializer_list{scan_reader_, move_reader_});
}

std::vector<Command> CommandReader::wait(std::chrono::milliseconds timeout) {
  std::vector<std::pair<dds_time_t, Command>> got;
  if (!waiter_->wait(timeout)) return {};
  const auto for_me = [&](const char* target) {
    return !target || !*target || robot_id_ == target;
  };
  dds::take_all<scanplan_ScanCommand>(
      scan_reader_, [&](const scanplan_ScanCommand& c, const dds_sample_info_t& info) {
        if (for_me(c.robot_id)) got.emplace_back(info.source_timestamp, ScanRequest{c.command_id});
      });
  dds::take_all<scanplan_MoveCommand>(
      move_reader_, [&](const scanplan_MoveCommand& c, const dds_sample_info_t& info) {
        if (for_me(c.robot_id)) {
          got.emplace_back(info.source_timestamp, MoveRequest{c.command_id, c.x, c.y, c.yaw_deg});
        }
      });
  std::stable_sort(got.begin(), got.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Command> out;
  for (auto& [t, c] : got) out.push_back(c);
  return out;
}

}  // namespace scanplan::bridge
