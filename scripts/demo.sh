#!/usr/bin/env bash
# Starts simulated scanner robots (ROBOTS=N, default 1) and the workstation on this machine, takes
# a first scan with each and prints the operator link. Ctrl-C stops them all.
# Robot k is "robotk"; robot 1 starts at the world's start, robot k at STARTk=x,y,yaw_deg if set,
# else 12 m farther east for each robot before it.
set -euo pipefail
build=${1:-build}
port=${2:-8080}
world=${WORLD:-samples/worlds/campus.json}
domain=${DOMAIN:-0}
session=${SESSION:-demo-session}
robots=${ROBOTS:-1}
if ! [[ $robots =~ ^[1-9][0-9]?$ ]]; then
  echo "ROBOTS must be a number of robots from 1 to 99, got '$robots'" >&2
  exit 2
fi

# Both processes run here, so keep DDS on loopback (lo often lacks the MULTICAST flag).
export CYCLONEDDS_URI=${CYCLONEDDS_URI:-'<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface address="127.0.0.1" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'}

pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT INT TERM

token=${SCANPLAN_OPERATOR_TOKEN:-$(head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n')}
export SCANPLAN_OPERATOR_TOKEN=$token

# The world's "start": [x, y, yaw_deg].
read -r start_x start_y start_yaw <<<"$(tr -d '\n' <"$world" | grep -o '"start"[^]]*' | tr -c '0-9.,-' ' ' | tr ',' ' ')"
for k in $(seq 1 "$robots"); do
  start_var=START$k
  start=${!start_var:-}
  if [[ -z $start && $k -gt 1 ]]; then
    start=$(awk -v x="$start_x" -v y="$start_y" -v yaw="$start_yaw" -v k="$k" \
      'BEGIN { printf "%g,%g,%g", x + 12 * (k - 1), y, yaw }')
  fi
  "$build/scanner_bridge/scanplan-bridge" --world "$world" --domain "$domain" --robot-id "robot$k" \
    --seed "$k" --time-scale "${TIME_SCALE:-6}" ${start:+--start "$start"} &
  pids+=($!)
done
"$build/server/scanplan-server" --session "$session" --listen "127.0.0.1:$port" --domain "$domain" &
pids+=($!)

# Ask for the first scan once the server answers and the bridge is matched on DDS.
for _ in $(seq 1 100); do
  if curl -sf "http://127.0.0.1:$port/api/v1/health" | grep -q "\"bridges\":$robots[,}]"; then
    curl -sf -X POST -H "Authorization: Bearer $token" "http://127.0.0.1:$port/api/v1/scan" >/dev/null &&
      break
  fi
  sleep 0.2
done

cat <<MSG

  scanplan demo is running (world: $world, robots: $robots)
  Open:           http://127.0.0.1:$port/?token=$token
  Operator token: $token
  Ask for another scan:
    curl -X POST -H "Authorization: Bearer $token" http://127.0.0.1:$port/api/v1/scan
  Ctrl-C stops the demo.

MSG
wait -n "${pids[@]}"
