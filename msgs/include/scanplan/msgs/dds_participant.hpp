#pragma once

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace scanplan::dds {

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws DdsError naming `what` when a Cyclone call failed; returns the value otherwise.
dds_return_t check(dds_return_t rc, std::string_view what);

// Settings a 300k-point scan needs to arrive whole without retransmit storms (STACK-NOTES:
// Cyclone's 14 720 B messages and 1 MiB receive buffer are too small for 5 MB samples).
// CYCLONEDDS_URI, when set, is applied after these and so wins.
std::string default_config();

// How long a bridge may show no sign of life on DDS before the server counts it as lost.
// Writers of scan data and status offer AUTOMATIC liveliness with this lease and the server's
// readers request the same. Cyclone asserts AUTOMATIC liveliness by itself (a participant message
// at 80 % of the lease, and every packet from the bridge renews it; the bridge also sends its
// status once a second), so a bridge that is killed, hangs in the kernel or loses its link is
// noticed within this time instead of after the 10 s participant lease, and a lost packet or two
// on a radio link does not count as death. Requested ≥ offered is DDS's matching rule: a writer
// offering a longer lease (a ROS 2 node's default is infinite) does not match these readers.
inline constexpr std::chrono::milliseconds kBridgeLivelinessLease{2000};

// How a topic's samples behave.
enum class QosKind {
  kScanData,  // reliable, keep the last few: scans are large and each one matters; bridge lease
  kCommand,   // reliable, keep all (bounded): a lost command is a robot that never moves
  kStatus,    // reliable, keep last 1: a newer status supersedes the older; bridge lease
  // reliable, keep last 1 (per instance for keyed types), transient-local: state that supersedes
  // itself and that a subscriber joining later must still get (the map, the plan, the goal, the
  // annotations), as a ROS 1 "latched" topic. Readers must ask for transient-local too to be
  // given the history.
  kLatched,
};

class Participant {
 public:
  explicit Participant(std::uint32_t domain_id);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return participant_; }
  // One topic entity per name, created on first use.
  dds_entity_t topic(const dds_topic_descriptor_t& type, const std::string& name);
  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& name, QosKind qos);
  // `listener` (may be null) is copied into the reader; its callbacks run on Cyclone's threads.
  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& name, QosKind qos,
                      const dds_listener_t* listener = nullptr);

 private:
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  std::map<std::string, dds_entity_t> topics_;
};

// Takes every available sample from `reader` (loaned, no copy) and calls fn(const T&) or
// fn(const T&, const dds_sample_info_t&) for each valid one. Returns how many were seen.
template <typename T, typename Fn>
int take_all(dds_entity_t reader, Fn&& fn) {
  constexpr int kBatch = 16;
  int seen = 0;
  for (;;) {
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    check(n, "dds_take");
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        if constexpr (std::is_invocable_v<Fn, const T&, const dds_sample_info_t&>) {
          fn(*static_cast<const T*>(samples[i]), infos[i]);
        } else {
          fn(*static_cast<const T*>(samples[i]));
        }
        ++seen;
      }
    }
    if (n > 0) check(dds_return_loan(reader, samples, n), "dds_return_loan");
    if (n < kBatch) return seen;
  }
}

// Blocks until one of `readers` has data or `timeout` passes; true when data is there.
class ReadWaiter {
 public:
  ReadWaiter(dds_entity_t participant, std::initializer_list<dds_entity_t> readers);
  ~ReadWaiter();
  ReadWaiter(const ReadWaiter&) = delete;
  ReadWaiter& operator=(const ReadWaiter&) = delete;
  bool wait(std::chrono::milliseconds timeout);

 private:
  dds_entity_t waitset_;
};

// Waits until `writer` is matched with at least one reader (or the timeout passes).
bool wait_for_reader(dds_entity_t writer, std::chrono::milliseconds timeout);

}  // namespace scanplan::dds
