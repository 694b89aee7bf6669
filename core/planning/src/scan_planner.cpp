#include "scanplan/planning/scan_planner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "scanplan/planning/scan_claims.hpp"
#include "scanplan/planning/scan_gain.hpp"
#include "scanplan/planning/travel_map.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace scanplan {

std::optional<PlannerPolicy> parse_policy(std::string_view name) {
  if (name == "paper") return PlannerPolicy::kPaper;
  if (name == "exhaustive") return PlannerPolicy::kExhaustive;
  if (name == "travel") return PlannerPolicy::kTravel;
  if (name == "nearest-frontier") return PlannerPolicy::kNearestFrontier;
  if (name == "random") return PlannerPolicy::kRandom;
  return std::nullopt;
}

std::string_view policy_name(PlannerPolicy policy) {
  switch (policy) {
    case PlannerPolicy::kPaper:
      return "paper";
    case PlannerPolicy::kExhaustive:
      return "exhaustive";
    case PlannerPolicy::kTravel:
      return "travel";
    case PlannerPolicy::kNearestFrontier:
      return "nearest-frontier";
    case PlannerPolicy::kRandom:
      return "random";
  }
  return "unknown";
}

namespace {

// Bounds on the baselines' searches: they look at candidates in their own order until enough
// are worth scanning, and give up (nothing worth scanning) after this many.
constexpr std::size_t kMaxBaselineEvaluations = 512;

void check_config(const PlannerConfig& c) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("planner config: " + what);
  };
  if (!(c.alpha >= 0 && c.alpha <= 1))
    fail("alpha must be in [0, 1], got " + std::to_string(c.alpha));
  if (c.hill_climb_starts < 1) fail("hill_climb_starts must be at least 1");
  if (!(c.hill_climb_step_m > 0)) fail("hill_climb_step_m must be greater than zero");
  if (c.hill_climb_samples < 0) fail("hill_climb_samples must be zero or more");
  if (c.screening_coarsening < 1) fail("screening_coarsening must be at least 1");
  if (!(c.lattice_m > 0)) fail("lattice_m must be greater than zero");
  if (!(c.completion_weight >= 0)) fail("completion_weight must be zero or more");
  if (c.max_candidates < 1) fail("max_candidates must be at least 1");
  if (!(c.travel_cost_per_m >= 0)) fail("travel_cost_per_m must be zero or more");
  if (!(c.travel_free_m >= 0)) fail("travel_free_m must be zero or more");
  if (!(c.candidate_separation_m >= 0)) fail("candidate_separation_m must be zero or more");
  if (!(c.claim_separation_m >= 0)) fail("claim_separation_m must be zero or more");
  if (!(c.robot_clearance_m >= 0)) fail("robot_clearance_m must be zero or more");
  if (!(c.refused_clearance_m >= 0)) fail("refused_clearance_m must be zero or more");
  if (!std::isfinite(c.min_gain_m2)) fail("min_gain_m2 must be finite");
  if (c.threads < 0) fail("threads must be zero (OpenMP default) or more");
  const RegistrabilityConfig& r = c.registrability;
  if (!(r.min_overlap_share > 0 && r.min_overlap_share <= 1))
    fail("registrability.min_overlap_share must be in (0, 1]");
  if (!(r.min_pose_fixing > 0 && std::isfinite(r.min_pose_fixing)))
    fail("registrability.min_pose_fixing must be greater than zero");
  if (!(r.absolute_fix_factor >= 1 && std::isfinite(r.absolute_fix_factor)))
    fail("registrability.absolute_fix_factor must be at least 1");
  if (!(r.floor_share >= 0 && r.floor_share <= 1))
    fail("registrability.floor_share must be in [0, 1]");
  if (!(r.reach_xy_m > 0) || !(r.reach_yaw_deg > 0))
    fail("registrability.reach_xy_m and reach_yaw_deg must be greater than zero");
  if (!(r.near_range_m > 0 && std::isfinite(r.near_range_m)))
    fail("registrability.near_range_m must be greater than zero");
  if (!std::isfinite(r.wall_min_extent_m)) fail("registrability.wall_min_extent_m must be finite");
}

// SplitMix64: a seeded stream that is the same on every platform and standard library.
class SplitMix {
 public:
  explicit SplitMix(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }

 private:
  std::uint64_t state_;
};

int thread_count(const PlannerConfig& cfg) {
#ifdef _OPENMP
  return cfg.threads > 0 ? cfg.threads : omp_get_max_threads();
#else
  (void)cfg;
  return 1;
#endif
}

int floor_mod(int a, int b) {
  return ((a % b) + b) % b;
}

// Movable cells a scan may be planned at, with what the policies need to know about them.
struct Sites {
  std::vector<CellIndex> cell;
  std::vector<float> floor_z;
  std::vector<double> travel_m;
  // drive_reach of the drive there; empty without drifting odometry or forecasts.
  std::vector<double> reach;
  double floor_share = 0;        // RegistrabilityConfig::floor_share
  CellGrid<std::int32_t> index;  // the movable region's geometry; -1 where no site
  std::size_t size() const { return cell.size(); }
  std::int32_t at(CellIndex c) const {
    const auto o = index.offset(c);
    return o ? index.values[*o] : -1;
  }
};

// Points of the other robots (claimed goals, where they stand), checked: each must be finite.
const std::vector<Eigen::Vector3d>& points_of(const std::vector<Eigen::Vector3d>* points,
                                              const char* what) {
  static const std::vector<Eigen::Vector3d> kNone;
  if (!points) return kNone;
  for (const Eigen::Vector3d& c : *points) {
    if (!c.allFinite()) throw std::invalid_argument(std::string("plan_next_scan: ") + what);
  }
  return *points;
}
const std::vector<Eigen::Vector3d>& claims_of(const PlanInput& in) {
  return points_of(in.claimed, "a claimed point is not finite");
}

// A disc no candidate may lie in: around another robot's goal, or around another robot.
struct KeepOut {
  Eigen::Vector2d centre;
  double radius2;
};

std::vector<KeepOut> keep_outs(const PlanInput& in, const PlannerConfig& cfg) {
  std::vector<KeepOut> out;
  for (const Eigen::Vector3d& c : claims_of(in)) {
    out.push_back({c.head<2>(), cfg.claim_separation_m * cfg.claim_separation_m});
  }
  for (const Eigen::Vector3d& r :
       points_of(in.occupied, "another robot's position is not finite")) {
    out.push_back({r.head<2>(), cfg.robot_clearance_m * cfg.robot_clearance_m});
  }
  if (in.refused) {
    for (const Eigen::Vector2d& r : *in.refused) {
      if (!r.allFinite())
        throw std::invalid_argument("plan_next_scan: a refused point is not finite");
      out.push_back({r, cfg.refused_clearance_m * cfg.refused_clearance_m});
    }
  }
  return out;
}

Sites collect_sites(const MlsMap& map, const MovableRegion& movable, const TravelMap& travel,
                    const TargetRegion* within, const std::vector<TargetRegion>& no_go,
                    const std::vector<KeepOut>& keep_out) {
  Sites s;
  const auto& g = movable.patch;
  s.index = CellGrid<std::int32_t>(g.origin, g.cols, g.rows, g.cell_m, -1);
  for (std::size_t o = 0; o < g.values.size(); ++o) {
    if (g.values[o] < 0) continue;
    const CellIndex c = g.index_at(o);
    const double d = travel.distance(c);
    if (!std::isfinite(d)) continue;
    // The robot may start outside the target region, but it scans only inside.
    const Eigen::Vector2d centre = map.center_of(c);
    if (within && !within->contains(centre.x(), centre.y())) continue;
    if (in_any(no_go, centre)) continue;
    // Another robot is going there, or standing there.
    if (std::any_of(keep_out.begin(), keep_out.end(), [&](const KeepOut& k) {
          return (k.centre - centre).squaredNorm() < k.radius2;
        })) {
      continue;
    }
    s.index.values[o] = static_cast<std::int32_t>(s.cell.size());
    s.cell.push_back(c);
    // The robot stands on the floor's surface: its mean height, the measured ground.
    s.floor_z.push_back(map.cell(c)->patches[g.values[o]].mean_z);
    s.travel_m.push_back(d);
  }
  return s;
}

struct Scored {
  std::int32_t site;
  ScanGain gain;
  double score = 0;
};

// What a policy ranks by, from a site and its gain.
using Scorer = std::function<double(std::int32_t site, const ScanGain& gain)>;
// A policy's score once the best F of a first look over the region is known.
using ScorerFor = std::function<Scorer(double best_f)>;

// F at the sites, through the plan's memo when it has one: an evaluation still valid is taken
// from it, one made afresh is queued per thread and kept once the parallel part is over. With
// drifting odometry each site's forecast then takes the drive there.
class SiteGains {
 public:
  SiteGains(const ScanGainEvaluator& gain, const Sites& sites, GainMemo* memo, int threads)
      : gain_(gain),
        sites_(sites),
        memo_(memo),
        fresh_(static_cast<std::size_t>(threads)),
        reused_(static_cast<std::size_t>(threads), 0),
        best_gain_(static_cast<std::size_t>(threads), 0.0) {}

  VisibilityPredictor::Workspace workspace() const { return gain_.workspace(); }

  ScanGain at(std::int32_t site, VisibilityPredictor::Workspace& ws) {
    const auto u = static_cast<std::size_t>(site);
    const CellIndex cell = sites_.cell[u];
    const float floor_z = sites_.floor_z[u];
    const std::size_t thread = thread_index();
    std::optional<ScanGain> found;
    if (memo_) found = memo_->find(gain_, cell, floor_z);
    ScanGain g;
    if (found) {
      g = std::move(*found);
      ++reused_[thread];
    } else {
      g = gain_.at(cell, floor_z, ws);
      if (memo_) fresh_[thread].push_back({cell, floor_z, g, ws.walks()});
    }
    best_gain_[thread] = std::max(best_gain_[thread], g.unscanned_m2 + g.low_resolution_m2);
    if (g.registrability && !sites_.reach.empty()) {
      Registrability& r = *g.registrability;
      r.reach = sites_.reach[u];
      if (r.reach < 1) r.factor = std::max(sites_.floor_share, r.factor * r.reach * r.reach);
    }
    return g;
  }

  // Keeps the fresh evaluations; returns how many were reused. Outside parallel parts only.
  std::size_t keep_fresh() {
    std::size_t reused = 0;
    for (const std::size_t r : reused_) reused += r;
    if (!memo_) return reused;
    for (auto& list : fresh_) {
      for (Fresh& f : list) memo_->keep(f.cell, f.floor_z, f.gain, std::move(f.walks));
      list.clear();
    }
    return reused;
  }

  // Plan::best_gain_m2. Outside parallel parts only.
  double best_gain() const { return *std::max_element(best_gain_.begin(), best_gain_.end()); }

 private:
  struct Fresh {
    CellIndex cell;
    float floor_z;
    ScanGain gain;
    std::vector<std::uint8_t> walks;
  };
  std::size_t thread_index() const {
#ifdef _OPENMP
    return std::min(static_cast<std::size_t>(omp_get_thread_num()), fresh_.size() - 1);
#else
    return 0;
#endif
  }

  const ScanGainEvaluator& gain_;
  const Sites& sites_;
  GainMemo* memo_;
  std::vector<std::vector<Fresh>> fresh_;
  std::vector<std::size_t> reused_;
  std::vector<double> best_gain_;
};

// With drifting odometry, each site's drive_reach.
void forecast_drives(Sites& sites, const DriveDrift* drift, const RegistrabilityConfig& cfg) {
  if (!drift || !cfg.enabled) return;
  sites.floor_share = cfg.floor_share;
  sites.reach.reserve(sites.size());
  for (const double d : sites.travel_m) sites.reach.push_back(drive_reach(*drift, d, cfg));
}

double by_gain(std::int32_t, const ScanGain& g) {
  return registrable_f(g);
}
Scorer gain_only(double) {
  return by_gain;
}

// F at the given sites, shared over the threads; the order of `which` is kept.
std::vector<Scored> evaluate_sites(SiteGains& gain, const std::vector<std::int32_t>& which,
                                   int threads, const Scorer& score = by_gain) {
  std::vector<Scored> out(which.size());
#pragma omp parallel num_threads(threads)
  {
    auto ws = gain.workspace();
#pragma omp for schedule(dynamic, 4)
    for (std::size_t k = 0; k < which.size(); ++k) {
      out[k].site = which[k];
      out[k].gain = gain.at(which[k], ws);
      out[k].score = score(which[k], out[k].gain);
    }
  }
  return out;
}

// Best score first, at least `separation` apart, only those worth scanning. Ties go to the
// lower site index so the order never depends on the threads.
std::vector<Scored> rank(std::vector<Scored> all, const Sites& sites, const PlannerConfig& cfg,
                         double cell_m) {
  all.erase(std::remove_if(all.begin(), all.end(),
                           [&](const Scored& s) { return s.gain.f < cfg.min_gain_m2; }),
            all.end());
  std::sort(all.begin(), all.end(), [](const Scored& a, const Scored& b) {
    return a.score != b.score ? a.score > b.score : a.site < b.site;
  });
  const double sep2 = std::pow(cfg.candidate_separation_m / cell_m, 2);
  std::vector<Scored> out;
  for (const Scored& s : all) {
    if (static_cast<int>(out.size()) == cfg.max_candidates) break;
    const CellIndex c = sites.cell[static_cast<std::size_t>(s.site)];
    const bool apart = std::all_of(out.begin(), out.end(), [&](const Scored& o) {
      const CellIndex p = sites.cell[static_cast<std::size_t>(o.site)];
      const double dx = c.x - p.x, dy = c.y - p.y;
      return s.site != o.site && dx * dx + dy * dy >= sep2;
    });
    if (apart) out.push_back(s);
  }
  return out;
}

std::vector<std::int32_t> lattice_sites(const Sites& sites, double lattice_m, double cell_m) {
  const int stride = std::max(1, static_cast<int>(std::lround(lattice_m / cell_m)));
  std::vector<std::int32_t> which;
  for (std::size_t s = 0; s < sites.size(); ++s) {
    if (floor_mod(sites.cell[s].x, stride) == 0 && floor_mod(sites.cell[s].y, stride) == 0) {
      which.push_back(static_cast<std::int32_t>(s));
    }
  }
  // A region narrower than the lattice still has somewhere to scan from.
  if (which.empty()) {
    which.resize(sites.size());
    std::iota(which.begin(), which.end(), 0);
  }
  return which;
}

// Where hill climbing starts, the sites already evaluated with the full fan to choose them,
// and the score it climbs (its scale set by the best F seen so far).
struct ClimbStarts {
  std::vector<std::int32_t> sites;
  std::vector<Scored> screened;
  Scorer score;
  std::size_t evaluations = 0;  // of the screening's sample, outside `screened`
};

// The starts are the best of a random sample rather than the sample's first few: the same
// randomised initial locations, but the climbs begin on the hills worth climbing. The sample is
// a lattice at a random offset, about hill_climb_samples cells on the movable region: random
// like the paper's starts, but spread evenly, so no part of the region is left without a start
// nearby. `screen` evaluates the sample (a sparser fan, PlannerConfig::screening_coarsening);
// the starts, and the site of the sample's best F that scales the score, are then evaluated
// with the full fan, so the score a climb compares and every F kept are the full fan's.
ClimbStarts screened_starts(SiteGains& gain, SiteGains& screen, const Sites& sites,
                            const PlannerConfig& cfg, int threads, const ScorerFor& scorer_for,
                            SplitMix& rng) {
  ClimbStarts out;
  const int stride = std::max(1, static_cast<int>(std::lround(std::sqrt(
                                     static_cast<double>(sites.size()) / cfg.hill_climb_samples))));
  const int ox = static_cast<int>(rng.below(static_cast<std::size_t>(stride)));
  const int oy = static_cast<int>(rng.below(static_cast<std::size_t>(stride)));
  std::vector<std::int32_t> sample;
  for (std::size_t s = 0; s < sites.size(); ++s) {
    if (floor_mod(sites.cell[s].x - ox, stride) == 0 &&
        floor_mod(sites.cell[s].y - oy, stride) == 0) {
      sample.push_back(static_cast<std::int32_t>(s));
    }
  }
  // A region thinner than the lattice still gets a start.
  if (sample.empty()) sample.push_back(static_cast<std::int32_t>(rng.below(sites.size())));
  std::vector<Scored> looked = evaluate_sites(screen, sample, threads);
  const auto best_f_of = [](const std::vector<Scored>& v) {
    double best = 0;
    for (const Scored& x : v) best = std::max(best, x.gain.f);
    return best;
  };
  const Scorer rough = scorer_for(best_f_of(looked));
  for (Scored& x : looked) x.score = rough(x.site, x.gain);
  std::vector<Scored> order = looked;
  std::stable_sort(order.begin(), order.end(),
                   [](const Scored& a, const Scored& b) { return a.score > b.score; });
  std::vector<std::int32_t> chosen;
  for (std::size_t k = 0;
       k < order.size() && static_cast<int>(chosen.size()) < cfg.hill_climb_starts; ++k) {
    chosen.push_back(order[k].site);
  }
  if (&screen == &gain) {
    out.screened = std::move(looked);  // already the full fan's
  } else {
    out.evaluations = looked.size();
    const auto most_f =
        std::max_element(looked.begin(), looked.end(), [](const Scored& a, const Scored& b) {
          return a.gain.f != b.gain.f ? a.gain.f < b.gain.f : a.site > b.site;
        });
    std::vector<std::int32_t> again = chosen;
    if (std::find(again.begin(), again.end(), most_f->site) == again.end())
      again.push_back(most_f->site);
    out.screened = evaluate_sites(gain, again, threads);
  }
  out.score = scorer_for(best_f_of(out.screened));
  for (Scored& x : out.screened) x.score = out.score(x.site, x.gain);
  out.sites = std::move(chosen);
  return out;
}

// The paper's own starts: random cells of the movable region, with no first look.
ClimbStarts random_starts(SiteGains& gain, const Sites& sites, const PlannerConfig& cfg,
                          const ScorerFor& scorer_for, SplitMix& rng) {
  ClimbStarts out;
  for (int k = 0; k < cfg.hill_climb_starts; ++k)
    out.sites.push_back(static_cast<std::int32_t>(rng.below(sites.size())));
  // The best F is that of the starts.
  double best_f = 0;
  auto ws = gain.workspace();
  for (const std::int32_t s : out.sites) best_f = std::max(best_f, gain.at(s, ws).f);
  out.evaluations = out.sites.size();
  out.score = scorer_for(best_f);
  return out;
}

// One climb from `start`: to the best 8-neighbour at the current move length while the score
// improves, then at half the move. Returns every site it evaluated, in order; `start_score`,
// when the start was evaluated already, is its score.
std::vector<Scored> climb(SiteGains& gain, const Sites& sites, std::int32_t start,
                          std::optional<double> start_score, int first_stride, const Scorer& score,
                          VisibilityPredictor::Workspace& ws) {
  static constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
  static constexpr int kDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  std::unordered_map<std::int32_t, double> memo;
  if (start_score) memo.emplace(start, *start_score);
  std::vector<Scored> seen;
  const auto value_at = [&](std::int32_t s) {
    const auto it = memo.find(s);
    if (it != memo.end()) return it->second;
    const ScanGain g = gain.at(s, ws);
    const double v = score(s, g);
    memo.emplace(s, v);
    seen.push_back({s, g, v});
    return v;
  };
  std::int32_t at = start;
  double value = value_at(at);
  for (int stride = first_stride; stride >= 1; stride /= 2) {
    for (;;) {
      std::int32_t best = -1;
      double best_value = value;
      const CellIndex c = sites.cell[static_cast<std::size_t>(at)];
      for (int n = 0; n < 8; ++n) {
        const std::int32_t s = sites.at({c.x + stride * kDx[n], c.y + stride * kDy[n]});
        if (s < 0) continue;
        const double v = value_at(s);
        if (v > best_value) {
          best_value = v;
          best = s;
        }
      }
      if (best < 0) break;
      at = best;
      value = best_value;
    }
  }
  return seen;
}

// Paper §3.4: hill climbing on F (or another score) from several random starts. Climbs run in
// parallel, each with its own memory of evaluated cells, so the result and the count of
// evaluations are the same whatever the thread count.
std::vector<Scored> hill_climb(SiteGains& gain, SiteGains& screen, const Sites& sites,
                               const PlannerConfig& cfg, double cell_m, int threads,
                               const ScorerFor& scorer_for, std::size_t& evaluations) {
  SplitMix rng(cfg.seed);
  const ClimbStarts starts =
      cfg.hill_climb_samples > 0
          ? screened_starts(gain, screen, sites, cfg, threads, scorer_for, rng)
          : random_starts(gain, sites, cfg, scorer_for, rng);
  const int first_stride =
      std::max(1, static_cast<int>(std::lround(cfg.hill_climb_step_m / cell_m)));
  std::vector<std::vector<Scored>> visited(starts.sites.size());
#pragma omp parallel num_threads(threads)
  {
    auto ws = gain.workspace();
#pragma omp for schedule(dynamic, 1)
    for (std::size_t k = 0; k < starts.sites.size(); ++k) {
      const std::int32_t start = starts.sites[k];
      const auto known = std::find_if(starts.screened.begin(), starts.screened.end(),
                                      [&](const Scored& s) { return s.site == start; });
      visited[k] =
          climb(gain, sites, start,
                known != starts.screened.end() ? std::optional(known->score) : std::nullopt,
                first_stride, starts.score, ws);
    }
  }
  std::vector<Scored> all;
  std::vector<bool> taken(sites.size(), false);
  evaluations = starts.evaluations + starts.screened.size();
  for (const Scored& s : starts.screened) {
    taken[static_cast<std::size_t>(s.site)] = true;
    all.push_back(s);
  }
  for (const auto& path : visited) {
    evaluations += path.size();
    for (const Scored& s : path) {
      if (taken[static_cast<std::size_t>(s.site)]) continue;
      taken[static_cast<std::size_t>(s.site)] = true;
      all.push_back(s);
    }
  }
  return all;
}

// Sites next to any cell of region `r`, or in it (for M, where the robot itself may stand).
std::vector<std::int32_t> frontier_sites(const Sites& sites, const RegionMap& regions, Region r) {
  std::vector<std::int32_t> out;
  for (std::size_t s = 0; s < sites.size(); ++s) {
    const CellIndex c = sites.cell[s];
    bool next_to = false;
    for (int dy = -1; dy <= 1 && !next_to; ++dy) {
      for (int dx = -1; dx <= 1 && !next_to; ++dx) {
        next_to = regions.at({c.x + dx, c.y + dy}) == r;
      }
    }
    if (next_to) out.push_back(static_cast<std::int32_t>(s));
  }
  return out;
}

// Evaluates `order` batch by batch and keeps the first max_candidates worth scanning (and
// apart from each other), in that order: the baselines' choice is their order, not F.
std::vector<Scored> first_worth_scanning(SiteGains& gain, const Sites& sites,
                                         const std::vector<std::int32_t>& order,
                                         const PlannerConfig& cfg, double cell_m, int threads,
                                         std::size_t& evaluations) {
  const double sep2 = std::pow(cfg.candidate_separation_m / cell_m, 2);
  std::vector<Scored> out;
  const std::size_t batch = static_cast<std::size_t>(std::max(8, 4 * threads));
  for (std::size_t begin = 0; begin < order.size() && evaluations < kMaxBaselineEvaluations &&
                              static_cast<int>(out.size()) < cfg.max_candidates;
       begin += batch) {
    const std::vector<std::int32_t> part(
        order.begin() + static_cast<std::ptrdiff_t>(begin),
        order.begin() + static_cast<std::ptrdiff_t>(std::min(order.size(), begin + batch)));
    evaluations += part.size();
    for (const Scored& s : evaluate_sites(gain, part, threads)) {
      if (static_cast<int>(out.size()) == cfg.max_candidates) break;
      if (s.gain.f < cfg.min_gain_m2) continue;
      const CellIndex c = sites.cell[static_cast<std::size_t>(s.site)];
      const bool apart = std::all_of(out.begin(), out.end(), [&](const Scored& o) {
        const CellIndex p = sites.cell[static_cast<std::size_t>(o.site)];
        const double dx = c.x - p.x, dy = c.y - p.y;
        return dx * dx + dy * dy >= sep2;
      });
      if (apart) out.push_back(s);
    }
  }
  return out;
}

// The floor nearest the robot within kFloorSearchCells whose top is within half a metre of
// the robot's height (movable_region's own tolerance), as x, y, z.
std::optional<Eigen::Vector3d> nearest_floor(const MlsMap& map, const Eigen::Vector3d& robot,
                                             const MovableConfig& config) {
  constexpr int kFloorSearchCells = 4;
  const CellIndex rc = map.index_of(robot.x(), robot.y());
  for (int r = 1; r <= kFloorSearchCells; ++r) {
    std::optional<Eigen::Vector3d> best;
    double best_d2 = 0;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        if (std::max(std::abs(dx), std::abs(dy)) != r) continue;
        const CellIndex c{rc.x + dx, rc.y + dy};
        const MlsCell* cell = map.cell(c);
        if (!cell) continue;
        for (int k = 0; k < cell->size; ++k) {
          const float z = cell->patches[k].max_z;
          if (std::abs(z - robot.z()) >= 0.5 || !is_floor(*cell, k, config)) continue;
          const double d2 = dx * dx + dy * dy;
          if (!best || d2 < best_d2) {
            const Eigen::Vector2d xy = map.center_of(c);
            best = Eigen::Vector3d(xy.x(), xy.y(), z);
            best_d2 = d2;
          }
        }
      }
    }
    if (best) return best;
  }
  return std::nullopt;
}

// The policy's choice among the sites, best first (PlannerConfig::policy).
std::vector<Scored> choose(const PlannerConfig& cfg, SiteGains& gain, SiteGains& screen,
                           const Sites& sites, const RegionMap& regions, double cell_m, int threads,
                           std::size_t& evaluations) {
  std::vector<Scored> chosen;
  switch (cfg.policy) {
    case PlannerPolicy::kPaper: {
      chosen = rank(hill_climb(gain, screen, sites, cfg, cell_m, threads, gain_only, evaluations),
                    sites, cfg, cell_m);
      break;
    }
    case PlannerPolicy::kExhaustive: {
      const double w = cfg.completion_weight;
      const Scorer with_completion = [w](std::int32_t, const ScanGain& g) {
        return registrable_f(g) + w * g.completed_m2;
      };
      auto all = evaluate_sites(gain, lattice_sites(sites, cfg.lattice_m, cell_m), threads,
                                with_completion);
      evaluations = all.size();
      chosen = rank(std::move(all), sites, cfg, cell_m);
      break;
    }
    case PlannerPolicy::kTravel: {
      // A metre of driving beyond travel_free_m costs travel_cost_per_m of the best F in view,
      // so the trade keeps its balance as the gains shrink over a mission. The drive is smooth
      // over the region, so the traded score is climbed as F is.
      const ScorerFor traded = [&](double best_f) -> Scorer {
        const double per_m = cfg.travel_cost_per_m * best_f;
        const double free_m = cfg.travel_free_m;
        return [&sites, per_m, free_m](std::int32_t site, const ScanGain& g) {
          const double drive = sites.travel_m[static_cast<std::size_t>(site)];
          return registrable_f(g) - per_m * std::max(0.0, drive - free_m);
        };
      };
      chosen = rank(hill_climb(gain, screen, sites, cfg, cell_m, threads, traded, evaluations),
                    sites, cfg, cell_m);
      break;
    }
    case PlannerPolicy::kNearestFrontier: {
      // Frontiers between the movable region and the unscanned region first (Yamauchi 1997);
      // once none is left, the low-resolution region's.
      auto order = frontier_sites(sites, regions, Region::kUnscanned);
      if (order.empty()) order = frontier_sites(sites, regions, Region::kLowResolution);
      std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
        return sites.travel_m[static_cast<std::size_t>(a)] <
               sites.travel_m[static_cast<std::size_t>(b)];
      });
      chosen = first_worth_scanning(gain, sites, order, cfg, cell_m, threads, evaluations);
      for (Scored& s : chosen) s.score = -sites.travel_m[static_cast<std::size_t>(s.site)];
      break;
    }
    case PlannerPolicy::kRandom: {
      SplitMix rng(cfg.seed);
      std::vector<std::int32_t> order;
      std::vector<bool> drawn(sites.size(), false);
      const std::size_t draws = std::min(sites.size(), kMaxBaselineEvaluations);
      while (order.size() < draws) {
        const std::size_t s = rng.below(sites.size());
        if (drawn[s]) continue;
        drawn[s] = true;
        order.push_back(static_cast<std::int32_t>(s));
      }
      chosen = first_worth_scanning(gain, sites, order, cfg, cell_m, threads, evaluations);
      break;
    }
  }

  return chosen;
}

// The sites chosen as the operator sees them, with the drive there.
std::vector<Candidate> to_candidates(const std::vector<Scored>& chosen, const Sites& sites,
                                     const MlsMap& map, const TravelMap& travel) {
  std::vector<Candidate> out;
  for (const Scored& s : chosen) {
    const auto u = static_cast<std::size_t>(s.site);
    Candidate c;
    const Eigen::Vector2d xy = map.center_of(sites.cell[u]);
    c.position = {xy.x(), xy.y(), sites.floor_z[u]};
    c.f = s.gain.f;
    c.gain_unscanned_m2 = s.gain.unscanned_m2;
    c.gain_low_res_m2 = s.gain.low_resolution_m2;
    c.gain_completed_m2 = s.gain.completed_m2;
    c.overlap_m2 = s.gain.overlap_m2;
    c.registrability = s.gain.registrability;
    c.travel_m = sites.travel_m[u];
    c.path = travel.path_to(sites.cell[u]);
    c.score = s.score;
    out.push_back(std::move(c));
  }
  return out;
}

// The anchored map on the regions' grid, when there is one to forecast the matcher on.
std::optional<RegistrabilityField> registrability_field(const PlanInput& in,
                                                        const PlannerConfig& cfg,
                                                        const RegionMap& regions) {
  if (!in.anchored) return std::nullopt;
  if (in.anchored->cell_m() != in.map.cell_m()) {
    throw std::invalid_argument(
        "plan_next_scan: the anchored map and the map must share one cell size");
  }
  return RegistrabilityField(*in.anchored, regions.cells.origin, regions.cells.cols,
                             regions.cells.rows, cfg.registrability);
}

// The segmentation and the movable region flooded from the robot; returns where the robot
// stands (its floor may lie a few cells off the reported position).
Eigen::Vector3d segment_and_flood(const PlanInput& in, const PlannerConfig& cfg, Plan& plan) {
  plan.regions = segment_regions(in.map, in.target, in.scan_points, cfg.regions);
  plan.movable = movable_region(in.map, in.robot, cfg.movable);
  if (plan.movable.cells > 0) return in.robot;
  // movable_region looks for the robot's floor within one cell. Gap filling between a ground
  // return and the foot of a low wall can leave a ramp of interpolated heights there, and once
  // the robot's own scan adds the real ground those cells are too deep to be floors; the robot
  // still stands on the ground a few cells away.
  if (const auto near = nearest_floor(in.map, in.robot, cfg.movable)) {
    plan.movable = movable_region(in.map, *near, cfg.movable);
    return *near;
  }
  return in.robot;
}

}  // namespace

Plan plan_next_scan(const PlanInput& in, const PlannerConfig& cfg) {
  check_config(cfg);
  if (!in.robot.allFinite())
    throw std::invalid_argument("plan_next_scan: the robot position is not finite");
  const std::vector<Eigen::Vector3d>& claims = claims_of(in);
  const std::vector<KeepOut> keep_out = keep_outs(in, cfg);
  const auto t0 = std::chrono::steady_clock::now();
  Plan plan;
  const auto finish = [&]() -> Plan {
    plan.plan_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return std::move(plan);
  };
  const Eigen::Vector3d start = segment_and_flood(in, cfg, plan);
  if (plan.movable.cells == 0 || plan.regions.unscanned + plan.regions.low_resolution == 0)
    return finish();

  const TravelMap travel = travel_map(in.map, plan.movable, start, cfg.movable,
                                      cfg.stay_in_target ? &in.target : nullptr, cfg.no_go);
  Sites sites = collect_sites(in.map, plan.movable, travel,
                              cfg.stay_in_target ? &in.target : nullptr, cfg.no_go, keep_out);
  forecast_drives(sites, in.drift, cfg.registrability);
  if (sites.size() == 0) return finish();
  // With claims, F is taken against the segmentation as it will be after the other robots'
  // scans; plan.regions stays the map's own.
  RegionMap claimed_regions;
  if (!claims.empty()) claimed_regions = plan.regions;
  const std::optional<RegistrabilityField> field = registrability_field(in, cfg, plan.regions);
  const ScanGainEvaluator gain(in.map, claims.empty() ? plan.regions : claimed_regions, cfg.alpha,
                               cfg.regions, cfg.visibility, field ? &*field : nullptr);
  if (!claims.empty())
    claim_predicted_scans(claimed_regions, gain.predictor(), claims, cfg.regions);
  // The memo, unless another plan holds it (then this one goes without).
  std::unique_lock<std::mutex> memo_lock;
  GainMemo* memo = nullptr;
  if (in.memo) {
    memo_lock = std::unique_lock<std::mutex>(in.memo->in_use(), std::try_to_lock);
    if (memo_lock.owns_lock()) {
      memo = in.memo;
      memo->begin(gain);
    }
  }
  const int threads = thread_count(cfg);
  SiteGains gains(gain, sites, memo, threads);
  // The climbs' screening looks through a sparser fan (PlannerConfig::screening_coarsening).
  std::optional<ScanGainEvaluator> rough;
  const bool climbs = cfg.policy == PlannerPolicy::kPaper || cfg.policy == PlannerPolicy::kTravel;
  if (climbs && cfg.hill_climb_samples > 0 && cfg.screening_coarsening > 1) {
    VisibilityConfig sparse = cfg.visibility;
    sparse.azimuth_step_deg = std::min(90.0, sparse.azimuth_step_deg * cfg.screening_coarsening);
    sparse.max_ray_spacing_m *= cfg.screening_coarsening;
    rough.emplace(in.map, claims.empty() ? plan.regions : claimed_regions, cfg.alpha, cfg.regions,
                  sparse, field ? &*field : nullptr);
  }
  std::optional<SiteGains> rough_gains;
  if (rough) rough_gains.emplace(*rough, sites, nullptr, threads);
  const std::vector<Scored> chosen =
      choose(cfg, gains, rough_gains ? *rough_gains : gains, sites, plan.regions, in.map.cell_m(),
             threads, plan.evaluations);
  plan.reused = gains.keep_fresh();
  // A place the screening saw gain at counts though no climb went there: while one is left the
  // mission is not done (Plan::best_gain_m2).
  plan.best_gain_m2 = std::max(gains.best_gain(), rough_gains ? rough_gains->best_gain() : 0.0);
  plan.ranked = to_candidates(chosen, sites, in.map, travel);
  return finish();
}

double evaluate(const PlanInput& in, const PlannerConfig& cfg, const Eigen::Vector3d& b,
                Candidate* detail) {
  check_config(cfg);
  if (!b.allFinite()) throw std::invalid_argument("evaluate: the scan point is not finite");
  const std::vector<Eigen::Vector3d>& claims = claims_of(in);
  RegionMap regions = segment_regions(in.map, in.target, in.scan_points, cfg.regions);
  const std::optional<RegistrabilityField> field = registrability_field(in, cfg, regions);
  const ScanGainEvaluator gain(in.map, regions, cfg.alpha, cfg.regions, cfg.visibility,
                               field ? &*field : nullptr);
  if (!claims.empty()) claim_predicted_scans(regions, gain.predictor(), claims, cfg.regions);
  const CellIndex c = in.map.index_of(b.x(), b.y());
  const ScanGain g = gain.at(c, b.z());
  if (detail) {
    const Eigen::Vector2d xy = in.map.center_of(c);
    detail->position = {xy.x(), xy.y(), b.z()};
    detail->f = detail->score = g.f;
    detail->gain_unscanned_m2 = g.unscanned_m2;
    detail->gain_low_res_m2 = g.low_resolution_m2;
    detail->gain_completed_m2 = g.completed_m2;
    detail->overlap_m2 = g.overlap_m2;
    detail->registrability = g.registrability;
  }
  return g.f;
}

}  // namespace scanplan
