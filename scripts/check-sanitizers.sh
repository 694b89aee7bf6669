#!/usr/bin/env bash
# make check-sanitizers: the unit and integration tests under AddressSanitizer with
# UndefinedBehaviorSanitizer, then under ThreadSanitizer, each in a build folder of its own
# (build-asan, build-tsan). Any report fails the run: the sanitizers write to log files, which
# are checked after the tests, so a report from a server a Node test started is not lost.
# Not part of `make test` (two more builds and slow tests); docs/architecture.md has its time.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
here=$(pwd)
# The page's browser tests add nothing the integration tests do not exercise on the server, and
# the guardrail checks are not compiled code.
exclude='^browser_|^clang_format$|^web_eslint$|^no_qt_or_vtk_linked$|^bridge_links_'

run() {
  local name=$1 sanitize=$2
  local dir=build-$name
  local logs=$here/$dir/sanitizer-logs
  echo "== $name: -fsanitize=$sanitize in $dir" >&2
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSANITIZE="$sanitize" >/dev/null
  cmake --build "$dir" -j"$jobs"
  rm -rf "$logs"
  mkdir -p "$logs"
  local started=$SECONDS status=0
  (
    cd "$dir"
    ASAN_OPTIONS="log_path=$logs/asan:detect_leaks=1:strict_string_checks=1" \
      LSAN_OPTIONS="suppressions=$here/tests/sanitizers/lsan.supp:print_suppressions=0" \
      UBSAN_OPTIONS="log_path=$logs/ubsan:print_stacktrace=1:halt_on_error=1" \
      TSAN_OPTIONS="log_path=$logs/tsan:second_deadlock_stack=1:suppressions=$here/tests/sanitizers/tsan.supp" \
      OMP_NUM_THREADS=${OMP_NUM_THREADS_UNDER_SANITIZER:-1} \
      ctest --output-on-failure -j"$jobs" -E "$exclude" --timeout 1200
  ) || status=$?
  echo "== $name: tests took $((SECONDS - started)) s (exit $status)" >&2
  if compgen -G "$logs/*" >/dev/null; then
    echo "== $name: sanitizer reports:" >&2
    for f in "$logs"/*; do
      echo "--- $f" >&2
      head -c 20000 "$f" >&2
    done
    status=1
  fi
  return $status
}

# check-sanitizers.sh [asan] [tsan]: both by default.
total=$SECONDS
for which in "${@:-asan tsan}"; do
  for w in $which; do
    case "$w" in
      asan) run asan address,undefined ;;
      tsan) run tsan thread ;;
      *) echo "unknown sanitizer run '$w' (asan or tsan)" >&2; exit 2 ;;
    esac
  done
done
echo "check-sanitizers: clean in $((SECONDS - total)) s" >&2
