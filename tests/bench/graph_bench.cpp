// Pose graph speed (issue 17): one optimisation after each scan, as the mission runs it, against
// the number of scans. A campus-like mission is drawn at random: stops 30–40 m apart over a
// 200 m × 160 m site, drifting odometry between consecutive stops (σ 2 % and 0.3° per 10 m of
// path, DESIGN.md), and a match edge (σ 2 cm, 0.05°) between every two stops within 45 m of
// each other, so that a robot coming back closes loops. Each step adds one scan and its edges
// and optimises from the previous solution (what MissionPipeline does); the baseline, in the
// same run, solves the same graph from the odometry alone (a batch solve, no warm start).
// One thread (the target: ≤ 100 ms at 60 scans on one core). Prints one JSON line.
// Usage: graph_bench [SCANS] [SEED]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "scanplan/graph/pose_graph.hpp"

namespace {

using namespace scanplan;
using Clock = std::chrono::steady_clock;

Eigen::Matrix4d information(double sigma_m, double sigma_deg) {
  const Eigen::Vector4d s(sigma_m, sigma_m, sigma_m, deg2rad(sigma_deg));
  return s.cwiseInverse().cwiseAbs2().asDiagonal();
}

RelativePose noisy(RelativePose r, double sigma_m, double sigma_deg, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  r.x += sigma_m * n(rng);
  r.y += sigma_m * n(rng);
  r.z += 0.1 * sigma_m * n(rng);
  r.yaw += deg2rad(sigma_deg) * n(rng);
  return r;
}

// Stops of a random walk over the site, each 30–40 m from the one before.
std::vector<Pose> mission(int scans, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> step(30, 40), turn(-M_PI, M_PI), yaw(-M_PI, M_PI);
  std::vector<Pose> out;
  Pose p;
  p.x = 100;
  p.y = 80;
  out.push_back(p);
  while (static_cast<int>(out.size()) < scans) {
    const double a = turn(rng), d = step(rng);
    Pose q = out.back();
    q.x += d * std::cos(a);
    q.y += d * std::sin(a);
    q.yaw = yaw(rng);
    if (q.x < 0 || q.x > 200 || q.y < 0 || q.y > 160) continue;
    out.push_back(q);
  }
  return out;
}

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const int scans = argc > 1 ? std::atoi(argv[1]) : 200;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  std::mt19937_64 rng(seed);
  const std::vector<Pose> truth = mission(scans, rng);

  PoseGraph incremental;
  std::vector<GraphEdge> edges;
  nlohmann::json steps = nlohmann::json::array();
  double worst_error = 0;
  for (int k = 0; k < scans; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    std::vector<GraphEdge> added;
    if (k > 0) {
      const RelativePose move = relative_pose(truth[i - 1], truth[i]);
      const double d = std::hypot(move.x, move.y) * 1.5;
      added.push_back({i - 1, i, noisy(move, 0.02 * d, 0.03 * d, rng),
                       information(0.02 * d, 0.03 * d), EdgeKind::kOdometry});
      for (std::size_t j = 0; j < i; ++j) {
        if (std::hypot(truth[j].x - truth[i].x, truth[j].y - truth[i].y) > 45) continue;
        added.push_back({j, i, noisy(relative_pose(truth[j], truth[i]), 0.02, 0.05, rng),
                         information(0.02, 0.05), EdgeKind::kMatch});
      }
    }
    // The new scan starts where its odometry puts it from the previous estimate.
    incremental.add_node(k == 0 ? truth[0]
                                : compose(incremental.pose(i - 1), added[0].measured, 0, 0));
    for (const GraphEdge& e : added) incremental.add_edge(e);
    edges.insert(edges.end(), added.begin(), added.end());
    auto t0 = Clock::now();
    const GraphSolveReport warm = incremental.optimise();
    const double warm_ms = ms_since(t0);

    const int n = k + 1;
    if (n == 10 || n == 30 || n == 60 || n == 100 || n == 150 || n == scans) {
      // Baseline: the same graph from the odometry chain, solved in one batch.
      PoseGraph batch;
      batch.add_node(truth[0]);
      for (std::size_t m = 1; m <= i; ++m) {
        const auto odo = std::find_if(edges.begin(), edges.end(), [&](const GraphEdge& e) {
          return e.kind == EdgeKind::kOdometry && e.to == m;
        });
        batch.add_node(compose(batch.pose(m - 1), odo->measured, 0, 0));
      }
      for (const GraphEdge& e : edges) batch.add_edge(e);
      t0 = Clock::now();
      const GraphSolveReport cold = batch.optimise();
      const double cold_ms = ms_since(t0);
      double error = 0;
      for (std::size_t m = 0; m <= i; ++m) {
        error = std::max(error, std::hypot(incremental.pose(m).x - truth[m].x,
                                           incremental.pose(m).y - truth[m].y));
      }
      worst_error = std::max(worst_error, error);
      steps.push_back({{"scans", n},
                       {"edges", edges.size()},
                       {"incremental_ms", warm_ms},
                       {"incremental_iterations", warm.iterations},
                       {"batch_ms", cold_ms},
                       {"batch_iterations", cold.iterations},
                       {"worst_error_m", error}});
    }
  }
  const nlohmann::json out = {{"bench", "pose_graph"},
                              {"seed", seed},
                              {"threads", 1},
                              {"steps", steps},
                              {"worst_error_m", worst_error}};
  std::printf("%s\n", out.dump().c_str());
  return 0;
}
