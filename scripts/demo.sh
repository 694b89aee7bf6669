#!/usr/bin/env bash
# Starts a simulated scanner robot and the workstation on this machine, takes a first scan and
# prints the operator link. Ctrl-C stops both.
set -euo pipefail
build=${1:-build}
port=${2:-8080}
world=${WORLD:-samples/worlds/campus.json}
domain=${DOMAIN:-0}
session=${SESSION:-demo-session}

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

"$build/scanner_bridge/scanplan-bridge" --world "$world" --domain "$domain" --time-scale "${TIME_SCALE:-6}" &
pids+=($!)
"$build/server/scanplan-server" --session "$session" --listen "127.0.0.1:$port" --domain "$domain" &
pids+=($!)

# Ask for the first scan once the server answers and the bridge is matched on DDS.
for _ in $(seq 1 100); do
  if curl -sf "http://127.0.0.1:$port/api/v1/health" | grep -q '"bridges":[1-9]'; then
    curl -sf -X POST -H "Authorization: Bearer $token" "http://127.0.0.1:$port/api/v1/scan" >/dev/null &&
      break
  fi
  sleep 0.2
done

cat <<MSG

  scanplan demo is running (world: $world)
  Open:           http://127.0.0.1:$port/?token=$token
  Operator token: $token
  Ask for another scan:
    curl -X POST -H "Authorization: Bearer $token" http://127.0.0.1:$port/api/v1/scan
  Ctrl-C stops the demo.

MSG
wait -n "${pids[@]}"
