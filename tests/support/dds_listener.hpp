#pragma once

// What the stand-alone DDS listeners (tests/integration/*_listener.cpp) share: plain Cyclone C
// calls with every return code checked, one JSON line on stdout per sample, and a clean stop on
// SIGTERM/SIGINT so the Node test that started them can end them.
#include <dds/dds.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace scanplan::test {

inline dds_return_t check(dds_return_t rc, const std::string& what) {
  if (rc < 0) throw std::runtime_error(what + " failed: " + dds_strretcode(rc));
  return rc;
}

inline void emit(const nlohmann::json& line) {
  std::fputs((line.dump() + "\n").c_str(), stdout);
  std::fflush(stdout);
}

inline std::atomic<bool> g_stop{false};

struct ListenerArgs {
  std::uint32_t domain = 0;
  int seconds = 120;                // a listener never outlives a hung test by much
  std::vector<std::string> robots;  // whose own topics (rt/<robot>/...) to follow as well
};

// --domain N [--seconds S] [--robots ID,ID]
inline ListenerArgs parse_listener_args(int argc, char** argv) {
  ListenerArgs a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--domain") {
      a.domain = static_cast<std::uint32_t>(std::stoul(argv[i + 1]));
    } else if (k == "--seconds") {
      a.seconds = std::stoi(argv[i + 1]);
    } else if (k == "--robots") {
      std::string list = argv[i + 1];
      for (std::size_t at = 0; at <= list.size();) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        if (comma > at) a.robots.push_back(list.substr(at, comma - at));
        at = comma + 1;
      }
    } else {
      throw std::runtime_error("unknown option " + k +
                               "; use --domain N [--seconds S] [--robots ID,ID]");
    }
  }
  return a;
}

// The QoS a subscriber to a latched topic asks for: reliable, keep last 1, transient-local, so
// the writer's kept sample is delivered on matching.
inline dds_qos_t* latched_reader_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  return q;
}

// ROS 2's default subscription QoS: reliable, keep last 10, volatile.
inline dds_qos_t* ros_default_reader_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  return q;
}

struct Subscription {
  dds_entity_t reader;
  // Called with each sample taken (valid or not: a disposal comes as an invalid sample).
  std::function<void(const void* sample, const dds_sample_info_t& info)> on_sample;
};

// Waits on every reader and hands their samples on until stopped or out of time.
inline void run_listener(dds_entity_t participant, const std::vector<Subscription>& subs,
                         int seconds) {
  std::signal(SIGTERM, [](int) { g_stop = true; });
  std::signal(SIGINT, [](int) { g_stop = true; });
  const dds_entity_t ws = check(dds_create_waitset(participant), "dds_create_waitset");
  for (const Subscription& s : subs) {
    check(dds_set_status_mask(s.reader, DDS_DATA_AVAILABLE_STATUS), "dds_set_status_mask");
    check(dds_waitset_attach(ws, s.reader, s.reader), "dds_waitset_attach");
  }
  emit({{"ready", true}});
  const dds_time_t deadline = dds_time() + DDS_SECS(seconds);
  while (!g_stop && dds_time() < deadline) {
    check(dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(100)), "dds_waitset_wait");
    for (const Subscription& s : subs) {
      for (;;) {
        void* samples[8] = {};
        dds_sample_info_t infos[8];
        const dds_return_t n = check(dds_take(s.reader, samples, infos, 8, 8), "dds_take");
        for (int i = 0; i < n; ++i) s.on_sample(samples[i], infos[i]);
        if (n > 0) check(dds_return_loan(s.reader, samples, n), "dds_return_loan");
        if (n < 8) break;
      }
    }
  }
  check(dds_delete(ws), "deleting the waitset");
}

}  // namespace scanplan::test
