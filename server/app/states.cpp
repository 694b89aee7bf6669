#include "app/states.hpp"

#include <array>
#include <utility>

namespace scanplan::server {
namespace {

template <typename E, std::size_t N>
std::string_view name_of(const std::array<std::pair<E, std::string_view>, N>& names, E value) {
  for (const auto& [e, text] : names) {
    if (e == value) return text;
  }
  return "unknown";
}

template <typename E, std::size_t N>
std::optional<E> parse(const std::array<std::pair<E, std::string_view>, N>& names,
                       std::string_view text) {
  for (const auto& [e, name] : names) {
    if (name == text) return e;
  }
  return std::nullopt;
}

constexpr std::array<std::pair<CandidateState, std::string_view>, 8> kCandidateStates{{
    {CandidateState::kProposed, "proposed"},
    {CandidateState::kMoving, "moving"},
    {CandidateState::kRejected, "rejected"},
    {CandidateState::kRefused, "refused"},
    {CandidateState::kReached, "reached"},
    {CandidateState::kCancelled, "cancelled"},
    {CandidateState::kInterrupted, "interrupted"},
    {CandidateState::kSuperseded, "superseded"},
}};

constexpr std::array<std::pair<RobotActivity, std::string_view>, 7> kActivities{{
    {RobotActivity::kUnknown, "unknown"},
    {RobotActivity::kIdle, "idle"},
    {RobotActivity::kMoving, "moving"},
    {RobotActivity::kArrived, "arrived"},
    {RobotActivity::kRefused, "refused"},
    {RobotActivity::kScanning, "scanning"},
    {RobotActivity::kOffline, "offline"},
}};

constexpr std::array<std::pair<ScanState, std::string_view>, 5> kScanStates{{
    {ScanState::kIdle, "idle"},
    {ScanState::kRequested, "requested"},
    {ScanState::kScanning, "scanning"},
    {ScanState::kDone, "done"},
    {ScanState::kFailed, "failed"},
}};

}  // namespace

std::string_view to_string(CandidateState state) {
  return name_of(kCandidateStates, state);
}

bool is_open(CandidateState state) {
  return state == CandidateState::kProposed || state == CandidateState::kInterrupted;
}

std::string_view to_string(RobotActivity activity) {
  return name_of(kActivities, activity);
}

RobotActivity parse_robot_activity(std::string_view text) {
  return parse(kActivities, text).value_or(RobotActivity::kUnknown);
}

std::string_view to_string(ScanState state) {
  return name_of(kScanStates, state);
}

std::optional<ScanState> parse_scan_state(std::string_view text) {
  return parse(kScanStates, text);
}

}  // namespace scanplan::server
