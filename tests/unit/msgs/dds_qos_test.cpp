// The QoS a bridge's writers offer and the server's readers request (docs/dds.md): scan data and
// status carry the bridge's liveliness lease, commands do not, and a writer offering no lease
// (DDS's default, infinite) is not matched by a reader that requests one.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <string>
#include <thread>

#include "scanplan.h"
#include "scanplan/msgs/dds_participant.hpp"
#include "scanplan/msgs/topics.hpp"
#include "test_domain.hpp"

namespace scanplan::dds {
namespace {

class DdsQos : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setenv("CYCLONEDDS_URI",
           "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface "
           "address=\"127.0.0.1\" multicast=\"true\"/></Interfaces></General></Domain>"
           "</CycloneDDS>",
           1);
  }

  struct Liveliness {
    dds_liveliness_kind_t kind;
    dds_duration_t lease;
  };
  static Liveliness liveliness_of(dds_entity_t entity) {
    dds_qos_t* qos = dds_create_qos();
    check(dds_get_qos(entity, qos), "dds_get_qos");
    Liveliness l{};
    EXPECT_TRUE(dds_qget_liveliness(qos, &l.kind, &l.lease));
    dds_delete_qos(qos);
    return l;
  }
  static std::uint32_t matched(dds_entity_t reader) {
    dds_subscription_matched_status_t st;
    check(dds_get_subscription_matched_status(reader, &st), "matched status");
    return st.current_count;
  }

  Participant participant_{test::test_domain()};
};

TEST_F(DdsQos, BridgeDataCarriesTheLivelinessLease) {
  const dds_duration_t lease = DDS_MSECS(kBridgeLivelinessLease.count());
  for (const QosKind kind : {QosKind::kScanData, QosKind::kStatus}) {
    const dds_entity_t w =
        participant_.writer(scanplan_RobotStatus_desc, topics::kRobotStatus, kind);
    const dds_entity_t r =
        participant_.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, kind);
    for (const dds_entity_t e : {w, r}) {
      const Liveliness l = liveliness_of(e);
      EXPECT_EQ(l.kind, DDS_LIVELINESS_AUTOMATIC);
      EXPECT_EQ(l.lease, lease);
    }
    EXPECT_GE(matched(r), 1u) << "offered lease = requested lease matches";
    dds_delete(w);
    dds_delete(r);
  }
}

TEST_F(DdsQos, CommandsCarryNoLease) {
  const dds_entity_t w =
      participant_.writer(scanplan_ScanCommand_desc, topics::kScanCommand, QosKind::kCommand);
  EXPECT_EQ(liveliness_of(w).lease, DDS_INFINITY);
  dds_delete(w);
}

TEST_F(DdsQos, AWriterWithoutALeaseIsNotMatchedByTheServersReaders) {
  const dds_entity_t topic = participant_.topic(scanplan_RobotStatus_desc, topics::kRobotStatus);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  const dds_entity_t w = check(dds_create_writer(participant_.handle(), topic, qos, nullptr),
                               "creating a writer with DDS's default liveliness");
  dds_delete_qos(qos);
  const dds_entity_t r =
      participant_.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus);
  EXPECT_EQ(matched(r), 0u);
  dds_requested_incompatible_qos_status_t st;
  check(dds_get_requested_incompatible_qos_status(r, &st), "incompatible QoS status");
  EXPECT_GE(st.total_count, 1u);
  EXPECT_EQ(st.last_policy_id, static_cast<std::uint32_t>(DDS_LIVELINESS_QOS_POLICY_ID));
  dds_delete(w);
  dds_delete(r);
}

// Status is keyed by robot: a burst of one robot's heartbeats, far deeper than the history, leaves
// another robot's refusal in the reader (keyless, it was pushed out and the move stayed "driving").
TEST_F(DdsQos, OneRobotsHeartbeatsDoNotPushOutAnothersRefusal) {
  const dds_entity_t w =
      participant_.writer(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus);
  const dds_entity_t r =
      participant_.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus);
  ASSERT_TRUE(wait_for_reader(w, std::chrono::seconds(5)));
  auto write = [&](const char* robot, const char* state, std::uint32_t command) {
    scanplan_RobotStatus s{};
    s.robot_id = const_cast<char*>(robot);
    s.command_id = command;
    s.state = const_cast<char*>(state);
    s.message = const_cast<char*>("");
    check(dds_write(w, &s), "dds_write status");
  };
  write("robot2", "refused", 7);
  for (std::uint32_t i = 0; i < 200; ++i) write("robot1", "idle", i);
  std::map<std::string, std::string> last;
  int robot1 = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < deadline &&
         (last["robot1"].empty() || !last.count("robot2"))) {
    take_all<scanplan_RobotStatus>(r, [&](const scanplan_RobotStatus& s) {
      last[s.robot_id] = s.state;
      if (std::string(s.robot_id) == "robot1") ++robot1;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(last["robot2"], "refused");
  EXPECT_EQ(last["robot1"], "idle");
  EXPECT_LE(robot1, 200);
  dds_delete(w);
  dds_delete(r);
}

}  // namespace
}  // namespace scanplan::dds
