// The server's bookkeeping of which robots' bridges are alive, fed the way DdsLink feeds it from
// Cyclone's liveliness changes and RobotStatus samples (handles are made up: no DDS here).
#include "dds/bridge_liveness.hpp"

#include <gtest/gtest.h>

namespace scanplan::server {
namespace {

using Cause = BridgeLiveness::Cause;

// One bridge process: a participant with its status writer and its scan data writers.
struct Bridge {
  BridgeLiveness::Handle participant, status, points, pose;
};
constexpr Bridge kFirst{100, 101, 102, 103};
constexpr Bridge kRestarted{200, 201, 202, 203};

// A bridge coming up: DDS matches its writers, then its first status names the robot.
void bring_up(BridgeLiveness& l, const Bridge& b, const std::string& robot) {
  for (const auto w : {b.status, b.points, b.pose}) EXPECT_FALSE(l.writer_alive(w, b.participant));
  l.announced(b.status, b.participant, robot);
}

TEST(BridgeLiveness, ARobotNeverSeenCountsAsConnected) {
  BridgeLiveness l;
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_TRUE(l.connected_robots().empty());
}

TEST(BridgeLiveness, FirstStatusMakesTheRobotKnownWithoutAnEvent) {
  BridgeLiveness l;
  for (const auto w : {kFirst.status, kFirst.points}) l.writer_alive(w, kFirst.participant);
  EXPECT_FALSE(l.announced(kFirst.status, kFirst.participant, "robot1"));
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_EQ(l.connected_robots(), std::vector<std::string>{"robot1"});
  // The status every second changes nothing.
  EXPECT_FALSE(l.announced(kFirst.status, kFirst.participant, "robot1"));
}

TEST(BridgeLiveness, AnExpiredLeaseLosesTheRobotOnceWithTheReason) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  // A killed bridge: DDS reports its writers one by one; the first one decides.
  const auto lost = l.writer_lost(kFirst.points, Cause::kLeaseExpired);
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->robot, "robot1");
  EXPECT_FALSE(lost->connected);
  EXPECT_NE(lost->reason.find("liveliness lease expired"), std::string::npos) << lost->reason;
  EXPECT_FALSE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));
  EXPECT_FALSE(l.writer_lost(kFirst.pose, Cause::kLeaseExpired));
  EXPECT_FALSE(l.connected("robot1"));
  EXPECT_TRUE(l.connected_robots().empty());
  EXPECT_TRUE(l.participant_lost(kFirst.participant));
  // Samples from any of its writers that are taken now are stale.
  EXPECT_TRUE(l.writer_from_lost_participant(kFirst.status));
  EXPECT_TRUE(l.writer_from_lost_participant(kFirst.pose));
}

TEST(BridgeLiveness, AStatusTakenAfterTheLeaseRanOutDoesNotReviveTheRobot) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  ASSERT_TRUE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));
  EXPECT_FALSE(l.announced(kFirst.status, kFirst.participant, "robot1"));
  EXPECT_FALSE(l.connected("robot1"));
}

TEST(BridgeLiveness, TheSameBridgeIsBackWhenItsStatusWriterIsAliveAgain) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  ASSERT_TRUE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));
  l.writer_lost(kFirst.points, Cause::kLeaseExpired);
  // A scan writer only revives with the next scan; that alone is no proof.
  EXPECT_FALSE(l.writer_alive(kFirst.points, kFirst.participant));
  EXPECT_FALSE(l.connected("robot1"));
  const auto back = l.writer_alive(kFirst.status, kFirst.participant);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->robot, "robot1");
  EXPECT_TRUE(back->connected);
  EXPECT_TRUE(back->reason.empty());
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_FALSE(l.writer_from_lost_participant(kFirst.points));
}

TEST(BridgeLiveness, ANewBridgeWithTheSameRobotIdBringsItBack) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  ASSERT_TRUE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));
  // The new process is matched before it names its robot: nothing to say yet.
  for (const auto w : {kRestarted.status, kRestarted.points}) {
    EXPECT_FALSE(l.writer_alive(w, kRestarted.participant));
  }
  EXPECT_FALSE(l.connected("robot1"));
  const auto back = l.announced(kRestarted.status, kRestarted.participant, "robot1");
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->connected);
  EXPECT_TRUE(l.connected("robot1"));
  // Ten seconds later DDS drops the dead participant's writers: the robot stays connected.
  for (const auto w : {kFirst.status, kFirst.points, kFirst.pose}) {
    EXPECT_FALSE(l.writer_lost(w, Cause::kLeft));
  }
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_FALSE(l.participant_lost(kFirst.participant)) << "forgotten once all its writers left";
  EXPECT_FALSE(l.knows_writer(kFirst.status));
}

TEST(BridgeLiveness, AStatusTakenBeforeItsWriterWasReportedAliveCountsAsAlive) {
  BridgeLiveness l;
  EXPECT_FALSE(l.announced(kFirst.status, kFirst.participant, "robot1"));
  EXPECT_FALSE(l.writer_alive(kFirst.status, kFirst.participant));
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_TRUE(l.knows_writer(kFirst.status));
}

TEST(BridgeLiveness, ABridgeThatShutsDownLeaves) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  const auto lost = l.writer_lost(kFirst.pose, Cause::kLeft);
  ASSERT_TRUE(lost);
  EXPECT_FALSE(lost->connected);
  EXPECT_EQ(lost->reason, BridgeLiveness::reason(Cause::kLeft));
  EXPECT_FALSE(l.writer_lost(kFirst.status, Cause::kLeft));
  EXPECT_FALSE(l.writer_lost(kFirst.points, Cause::kLeft));
  EXPECT_FALSE(l.connected("robot1"));
  // A writer DDS never mentioned, or one already gone, changes nothing.
  EXPECT_FALSE(l.writer_lost(999, Cause::kLeaseExpired));
  EXPECT_FALSE(l.writer_lost(kFirst.points, Cause::kLeft));
}

TEST(BridgeLiveness, AGoodbyeLosesTheRobotAtOnceAsShutDown) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  const auto lost = l.said_goodbye(kFirst.status);
  ASSERT_TRUE(lost);
  EXPECT_FALSE(lost->connected);
  EXPECT_EQ(lost->reason, "the bridge shut down");
  // DDS then reports the writers going (first as not alive, then gone): nothing new.
  EXPECT_FALSE(l.writer_lost(kFirst.points, Cause::kLeaseExpired));
  EXPECT_FALSE(l.writer_lost(kFirst.points, Cause::kLeft));
  EXPECT_FALSE(l.said_goodbye(kFirst.status));
  EXPECT_FALSE(l.connected("robot1"));
  EXPECT_FALSE(l.said_goodbye(999)) << "an unknown writer";
}

TEST(BridgeLiveness, TwoBridgesLostTogetherAreBothReported) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  bring_up(l, kRestarted, "robot2");
  EXPECT_EQ(l.connected_robots(), (std::vector<std::string>{"robot1", "robot2"}));
  const auto a = l.writer_lost(kFirst.status, Cause::kLeaseExpired);
  const auto b = l.writer_lost(kRestarted.points, Cause::kLeaseExpired);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->robot, "robot1");
  EXPECT_EQ(b->robot, "robot2");
  EXPECT_TRUE(l.connected_robots().empty());
}

TEST(BridgeLiveness, TwoBridgesForOneRobotLoseItOnlyWhenBothAreGone) {
  BridgeLiveness l;
  bring_up(l, kFirst, "robot1");
  bring_up(l, kRestarted, "robot1");
  EXPECT_FALSE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_TRUE(l.writer_lost(kRestarted.status, Cause::kLeaseExpired));
  EXPECT_FALSE(l.connected("robot1"));
}

TEST(BridgeLiveness, ABridgeLostBeforeItsFirstStatusIsNotHeldAgainstItsRobot) {
  BridgeLiveness l;
  l.writer_alive(kFirst.status, kFirst.participant);
  EXPECT_FALSE(l.writer_lost(kFirst.status, Cause::kLeaseExpired));  // no robot to report
  // Its link comes back: the status writer is alive again, then its status names the robot.
  EXPECT_FALSE(l.writer_alive(kFirst.status, kFirst.participant));
  EXPECT_FALSE(l.announced(kFirst.status, kFirst.participant, "robot1"));
  EXPECT_TRUE(l.connected("robot1"));
  EXPECT_EQ(l.connected_robots(), std::vector<std::string>{"robot1"});
}

}  // namespace
}  // namespace scanplan::server
