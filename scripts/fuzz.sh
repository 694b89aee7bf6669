#!/usr/bin/env bash
# make fuzz: each fuzz target (tests/fuzz) built with clang for libFuzzer under ASan+UBSan in
# build-fuzz/, then run for FUZZ_SECONDS (default 120) each, or FUZZ_RUNS executions each when
# that is set (issue 16's bar: 10000000), one after another, starting from its
# committed corpus (tests/fuzz/corpus/<name>/; new inputs go to build-fuzz/corpus/<name>/, not
# into the repository). A crash, a leak or a sanitizer report stops the run with the input saved
# in build-fuzz/artifacts/. Inputs are at most FUZZ_MAX_LEN bytes (default 8192: the parsers' size
# limits are scaled down in the targets, and short inputs keep the rate up). Prints one JSON line
# per target: executions, seconds, corpus size.
# `make test` replays the committed corpora without clang.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --fuzz
seconds=${FUZZ_SECONDS:-120}
limit=(-max_total_time="$seconds")
[ -n "${FUZZ_RUNS:-}" ] && limit=(-runs="$FUZZ_RUNS")
jobs=${JOBS:-2}
targets=(http_request websocket_frame ply pcd threedtk world_json rest_bodies)
[ $# -gt 0 ] && targets=("$@")
dir=build-fuzz
CC=clang CXX=clang++ cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSANITIZE=address,undefined -DSCANPLAN_FUZZ=ON >/dev/null
cmake --build "$dir" -j"$jobs" --target "${targets[@]/#/fuzz_}"
mkdir -p "$dir/artifacts"
for t in "${targets[@]}"; do
  work="$dir/corpus/$t"
  mkdir -p "$work"
  log="$dir/fuzz_$t.log"
  echo "== fuzz_$t: ${limit[*]}" >&2
  started=$SECONDS
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
    "$dir/tests/fuzz/fuzz_$t" "${limit[@]}" -rss_limit_mb=2048 -max_len="${FUZZ_MAX_LEN:-8192}" \
    -artifact_prefix="$dir/artifacts/${t}_" -print_final_stats=1 \
    "$work" "tests/fuzz/corpus/$t" >"$log" 2>&1 || {
    tail -50 "$log" >&2
    echo "fuzz_$t failed: the input is in $dir/artifacts/" >&2
    exit 1
  }
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  corpus=$(find "$work" -type f | wc -l)
  echo "{\"fuzz\":\"$t\",\"seconds\":$((SECONDS - started)),\"executions\":$runs,\"corpus\":$corpus,\"crashes\":0}"
done
