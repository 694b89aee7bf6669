// The server's map follows the pose graph (issue 17): a scan no match places waits outside the
// map (not encoded, not in the thinned map or the bounds); once two scans around it tie it in,
// it joins at its true pose, the correction names it, and its chunk is made anew where it now
// is. On the yard world with known true poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "app/live_map.hpp"
#include "ground_pose.hpp"
#include "quick_yard.hpp"
#include "scanplan/compression/draco_codec.hpp"

namespace scanplan::server {
namespace {

constexpr auto* at = &testing_support::ground_pose;
using testing_support::quick_yard;
using testing_support::quick_yard_scan;

class LiveMapGraphTest : public ::testing::Test {
 protected:
  LiveMapGraphTest() : map_(plans_, config()) {}
  static MissionConfig config() {
    MissionConfig c;
    c.mapping.sensor_height_m = quick_yard().scanner.mount_height_m;
    c.planner.policy = PlannerPolicy::kExhaustive;
    return c;
  }
  // Scan `id` taken at `truth`, reported at `reported`, matched as the server matches it.
  LiveMap::Added add(std::int64_t id, const Pose& truth, const Pose& reported, bool match = true) {
    StoredScan s;
    s.id = id;
    s.robot = "robot1";
    s.estimated = reported;
    s.placed = reported;
    const PointCloud cloud = quick_yard_scan(truth, id);
    s.points = cloud.size();
    if (match) {
      if (const auto m = map_.place(cloud, reported, s.robot)) {
        s.match = StoredMatch{
            m->applied, m->result.converged,    m->result.method, "",
            0,          m->result.inlier_ratio, m->information,   m->result.weakest_constraint};
        s.placed = m->placed;
      }
    }
    return map_.add(s, cloud);
  }
  PlanBook plans_;
  LiveMap map_;
};

Eigen::Vector3d centroid(const PointCloud& c) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : c.points) sum += p.cast<double>();
  return sum / static_cast<double>(c.size());
}

TEST_F(LiveMapGraphTest, AScanTiedInLaterJoinsTheMapWhereItBelongs) {
  add(1, at(-15, -8, 0), at(-15, -8, 0));
  const std::size_t points_one = map_.point_count();
  // Unmatched (as a refused match leaves it), 2 m off: it waits outside the map.
  const LiveMap::Added second = add(2, at(-5, -9, 0), at(-3, -7, 0), /*match=*/false);
  EXPECT_FALSE(second.in_map);
  EXPECT_EQ(map_.waiting(), std::vector<std::int64_t>{2});
  // The operator reads why (GET /api/v1/scans `outside`): its pairwise match with the first
  // waits for a second that agrees.
  const std::map<std::int64_t, std::string> why = map_.waiting_reasons();
  ASSERT_EQ(why.size(), 1u);
  EXPECT_EQ(why.at(2), "a pairwise match with a scan in the map waits for a second that agrees");
  EXPECT_EQ(map_.point_count(), points_one) << "a waiting scan's points are not in the map";
  EXPECT_FALSE(map_.encoded_range(1, 2).draco) << "nor in what a page fetches of the map";
  ASSERT_EQ(second.corrected.poses.size(), 1u) << "its pose is recorded as waiting";
  EXPECT_FALSE(second.corrected.poses[0].in_map);

  // A third scan, placed by its match: its pairwise match agrees with the first on where the
  // second lies, and that ties the second in.
  const LiveMap::Added third = add(3, at(-12, 4, 30), at(-12, 4, 30));
  EXPECT_TRUE(third.in_map);
  EXPECT_TRUE(map_.waiting().empty());
  EXPECT_TRUE(map_.waiting_reasons().empty());
  EXPECT_EQ(third.corrected.joined, std::vector<std::int64_t>{2});
  EXPECT_FALSE(third.plans.empty()) << "planned on the corrected map";
  const auto scans = map_.scans();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_NEAR(scans[1].placed.x, -5, 0.03);
  EXPECT_NEAR(scans[1].placed.y, -9, 0.03);
  const auto revised = std::find_if(third.corrected.poses.begin(), third.corrected.poses.end(),
                                    [](const RevisedPose& r) { return r.scan == 2; });
  ASSERT_NE(revised, third.corrected.poses.end());
  EXPECT_TRUE(revised->in_map);
  EXPECT_NEAR(revised->pose.x, -5, 0.03);

  // Its chunk is where it now is: its points' centroid as the true pose puts them.
  const auto chunk = map_.encoded_chunk(2);
  ASSERT_TRUE(chunk);
  const PointCloud decoded = decode_draco(*chunk);
  const PointCloud own = quick_yard_scan(at(-5, -9, 0), 2);
  const Eigen::Vector3d truth = at(-5, -9, 0).isometry() * centroid(own);
  EXPECT_LT((centroid(decoded) - truth).norm(), 0.05);
  EXPECT_GT(map_.point_count(), points_one + decoded.size());
}

TEST_F(LiveMapGraphTest, ARebuildKeepsTheGraphsPlacement) {
  add(1, at(-15, -8, 0), at(-15, -8, 0));
  add(2, at(-5, -9, 0), at(-3, -7, 0), /*match=*/false);
  add(3, at(-12, 4, 30), at(-12, 4, 30));
  // The operator takes nothing out: the map made anew from the same scans puts the second scan
  // where the graph did, from the stored match evidence alone.
  std::vector<StoredScan> keep = map_.scans();
  keep[1].placed = at(-3, -7, 0);  // as stored: where its refused match left it
  const LiveMap::Rebuilt rebuilt =
      map_.rebuild(keep, [](const StoredScan&) -> PointCloud { throw std::runtime_error("held"); });
  EXPECT_TRUE(rebuilt.skipped.empty());
  const auto scans = map_.scans();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_NEAR(scans[1].placed.x, -5, 0.03);
  EXPECT_NEAR(scans[1].placed.y, -9, 0.03);
  EXPECT_TRUE(map_.waiting().empty());
}

}  // namespace
}  // namespace scanplan::server
