// Matches made ahead of their turn (pairwise matches, re-matches of refused scans) must give
// what a match-by-match pass gives, on any thread count.
#include "scanplan/mission/ahead_of_turn.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace scanplan {
namespace {

struct Pass {
  std::vector<int> results;  // in the order used
  int matches = 0;           // made, ahead or in turn
};

// Item i starts from state[i]; using an even item moves where the next one starts, as a scan
// tied in by one pair changes where the next pair's search starts.
Pass run(int threads, int items, int throw_at = -1) {
  std::vector<int> state(static_cast<std::size_t>(items), 0);
  Pass pass;
  const auto start_of = [&](std::size_t i) { return state[i]; };
  const auto match = [&](std::size_t i, int start) {
#pragma omp atomic
    ++pass.matches;
    if (static_cast<int>(i) == throw_at) throw std::runtime_error("no overlap");
    return 100 * start + static_cast<int>(i);
  };
  const auto use = [&](std::size_t i, int result) {
    pass.results.push_back(result);
    if (i % 2 == 0 && i + 1 < state.size()) state[i + 1] += 7;
  };
  try {
    detail::match_ahead_of_turn(static_cast<std::size_t>(items), threads, start_of, match, use);
  } catch (const std::runtime_error&) {
    pass.results.push_back(-1);
  }
  return pass;
}

TEST(AheadOfTurn, ResultsAreThoseOfAPassInTurnOnAnyThreadCount) {
  const Pass one = run(1, 9);
  ASSERT_EQ(one.results.size(), 9u);
  EXPECT_EQ(one.results[1], 701);  // item 1 started where item 0 left it
  EXPECT_EQ(one.matches, 9);
  for (const int threads : {2, 3, 4}) {
    const Pass many = run(threads, 9);
    EXPECT_EQ(many.results, one.results) << threads << " threads";
#ifdef _OPENMP
    // The items whose start moved were made again in turn.
    EXPECT_GT(many.matches, one.matches) << threads << " threads";
#endif
  }
}

TEST(AheadOfTurn, AFailureIsRaisedInItsTurn) {
  const Pass one = run(1, 6, 3);
  EXPECT_EQ(one.results, (std::vector<int>{0, 701, 2, -1}));
  for (const int threads : {2, 4}) EXPECT_EQ(run(threads, 6, 3).results, one.results);
}

}  // namespace
}  // namespace scanplan
