#!/usr/bin/env bash
# Starts simulated scanner robots (ROBOTS=N, default 1) and the workstation on this machine, sets
# the mission's target area to the world's bounds, takes a first scan with each and prints the
# operator and viewer links. Each run is a fresh session under sessions/ unless SESSION=DIR names
# one to resume. Ctrl-C stops them all.
# Robot k is "robotk"; robot 1 starts at the world's start, robot k at STARTk=x,y,yaw_deg if set,
# else 12 m farther east for each robot before it.
set -euo pipefail
build=${1:-build}
port=${2:-8080}
world=${WORLD:-samples/worlds/campus.json}
domain=${DOMAIN:-0}
session=${SESSION:-sessions/demo-$(date +%Y%m%d-%H%M%S)}
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

new_token() { head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n'; }
token=${SCANPLAN_OPERATOR_TOKEN:-$(new_token)}
viewer_token=${SCANPLAN_VIEWER_TOKEN:-$(new_token)}
export SCANPLAN_OPERATOR_TOKEN=$token SCANPLAN_VIEWER_TOKEN=$viewer_token

# The world's target region as PUT /api/v1/params takes it: its polygon, or its bounds' corners.
# Without it the server plans over a 200 m square around the first scan, most of it outside a
# smaller world, and the robot refuses every point there.
area=$(node -e '
  const w = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
  const b = w.bounds ?? {};
  const corners = b.polygon ?? [b.min, [b.max[0], b.min[1]], b.max, [b.min[0], b.max[1]]];
  process.stdout.write(JSON.stringify({ target: corners, by: "make demo (the world'"'"'s bounds)" }));
' "$world")

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

# Set the area and ask for the first scan once the server answers and the bridges are matched
# on DDS. A resumed session keeps the area its operator last set, if one did.
for _ in $(seq 1 100); do
  if curl -sf "http://127.0.0.1:$port/api/v1/health" | grep -q "\"bridges\":$robots[,}]"; then
    if curl -sf -H "Authorization: Bearer $token" "http://127.0.0.1:$port/api/v1/params" |
      grep -q '"target":null'; then
      curl -sf -X PUT -H "Authorization: Bearer $token" --data "$area" \
        "http://127.0.0.1:$port/api/v1/params" >/dev/null ||
        echo "could not set the target area to the world's bounds" >&2
    fi
    curl -sf -X POST -H "Authorization: Bearer $token" "http://127.0.0.1:$port/api/v1/scan" >/dev/null &&
      break
  fi
  sleep 0.2
done

cat <<MSG

  scanplan demo is running (world: $world, robots: $robots, session: $session)
  Operator:       http://127.0.0.1:$port/?token=$token
  Viewer (read-only, for other teams): http://127.0.0.1:$port/?token=$viewer_token
  Operator token: $token
  Resume this session later: SESSION=$session make demo
  Ask for another scan:
    curl -X POST -H "Authorization: Bearer $token" http://127.0.0.1:$port/api/v1/scan
  Ctrl-C stops the demo.

MSG
wait -n "${pids[@]}"
