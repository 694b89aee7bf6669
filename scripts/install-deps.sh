#!/usr/bin/env bash
# Installs what scanplan needs on Debian bookworm, and nothing when all of it is there already.
set -euo pipefail

packages=(
  build-essential cmake ccache pkg-config clang-format curl
  cyclonedds-dev cyclonedds-tools
  libeigen3-dev libdraco-dev libopencv-dev nlohmann-json3-dev libcli11-dev libspdlog-dev libssl-dev
  libsqlite3-dev libceres-dev
  libgtest-dev libgmock-dev libbenchmark-dev libpcl-dev libnanoflann-dev
  nodejs npm chromium
)
# Benchmarks only (tests/bench/http_bench.sh): the load generator and the baseline server.
[ "${1:-}" = "--bench" ] && packages+=(wrk nginx-light)
# make fuzz only: clang with its libFuzzer and sanitizer runtimes.
[ "${1:-}" = "--fuzz" ] && packages+=(clang)

missing=()
for p in "${packages[@]}"; do
  # Nodejs and npm may come from outside Debian (e.g. a preinstalled Node 20): accept the command.
  case "$p" in
    nodejs) command -v node >/dev/null && continue ;;
    npm) command -v npm >/dev/null && continue ;;
  esac
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
