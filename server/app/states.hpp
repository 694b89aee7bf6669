#pragma once

#include <optional>
#include <string_view>

namespace scanplan::server {

// Where a suggested scan point stands in the operator's decisions (docs/api.md "Candidates").
enum class CandidateState {
  kProposed,     // waiting for the operator
  kMoving,       // approved: the robot is driving there
  kRejected,     // the operator said no
  kRefused,      // the robot said it cannot get there
  kReached,      // the robot arrived (and scans)
  kCancelled,    // the operator stopped the move
  kInterrupted,  // the robot's bridge was lost on the way; may be approved again
  kSuperseded,   // a newer plan replaced it before anyone decided
};
std::string_view to_string(CandidateState state);
// Whether the operator may still approve or reject it.
bool is_open(CandidateState state);

// What a robot last said it is doing (scanplan_RobotStatus.state on the wire).
enum class RobotActivity { kUnknown, kIdle, kMoving, kArrived, kRefused, kScanning, kOffline };
std::string_view to_string(RobotActivity activity);
// kUnknown for anything a bridge may say that this server does not know.
RobotActivity parse_robot_activity(std::string_view text);

// How far a robot's current scan has come: from the command (requested), through the
// scanner's progress reports (scanning, done), or lost with the bridge (failed).
enum class ScanState { kIdle, kRequested, kScanning, kDone, kFailed };
std::string_view to_string(ScanState state);
// nullopt for a progress state this server does not know.
std::optional<ScanState> parse_scan_state(std::string_view text);

}  // namespace scanplan::server
