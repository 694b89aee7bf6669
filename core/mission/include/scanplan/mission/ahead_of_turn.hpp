#pragma once

// Matches made ahead of their turn, as many at once as there are cores, and used in turn: a
// result is taken only if what it started from is the same when its turn comes, else it is made
// again then. The graph a pass makes is therefore the one a match-by-match pass makes, whatever
// the thread count; the cores only save time while earlier results leave later starts alone.

#include <algorithm>
#include <cstddef>
#include <exception>
#include <optional>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace scanplan::detail {

// For i in [0, n): start_of(i) is what match(i, start) depends on (compared with ==),
// match(i, start) reads shared state only, use(i, result) may change it and runs in order on
// the calling thread. `threads` 0 or less: the OpenMP default.
template <typename StartOf, typename Match, typename Use>
void match_ahead_of_turn(std::size_t n, int threads, const StartOf& start_of, const Match& match,
                         const Use& use) {
  using Start = decltype(start_of(std::size_t{0}));
  using Result = decltype(match(std::size_t{0}, start_of(std::size_t{0})));
#ifdef _OPENMP
  // Inside a parallel region already (a caller sharing its own work): one at a time.
  const int available = omp_in_parallel() ? 1 : threads > 0 ? threads : omp_get_max_threads();
#else
  const int available = 1;
  (void)threads;
#endif
  const auto cores = static_cast<std::size_t>(std::max(1, available));
  for (std::size_t first = 0; first < n;) {
    const std::size_t count = std::min(cores, n - first);
    std::vector<Start> starts;
    std::vector<std::optional<Result>> ahead(count);
    // An exception must not leave a parallel region: it is raised in its turn instead.
    std::vector<std::exception_ptr> failed(count);
    if (count > 1) {
      for (std::size_t b = 0; b < count; ++b) starts.push_back(start_of(first + b));
      const int team = static_cast<int>(count);
#pragma omp parallel for schedule(dynamic, 1) num_threads(team)
      for (long long b = 0; b < team; ++b) {
        const auto u = static_cast<std::size_t>(b);
        try {
          ahead[u].emplace(match(first + u, starts[u]));
        } catch (...) {
          failed[u] = std::current_exception();
        }
      }
    }
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t i = first + b;
      Start now = start_of(i);
      if (count == 1 || !(now == starts[b])) {
        ahead[b].emplace(match(i, now));
      } else if (failed[b]) {
        std::rethrow_exception(failed[b]);
      }
      use(i, std::move(*ahead[b]));
    }
    first += count;
  }
}

}  // namespace scanplan::detail
