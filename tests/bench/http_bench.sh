#!/usr/bin/env bash
# GET /api/v1/session against nginx serving a static file of the same size (issue 7 target:
# at least 50 % of nginx's throughput), both with wrk on loopback, 2 threads, 64 connections,
# in the same run. The session first holds the recorded campus scans (samples/replays/campus),
# so the answer is the one an operator's page polls. Usage after `make build`:
#   tests/bench/http_bench.sh [SECONDS]
# Installs wrk and nginx-light when missing (scripts/install-deps.sh --bench). Prints one JSON
# line.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD:-$src/build}
seconds=${1:-10}
"$src/scripts/install-deps.sh" --bench

work=$(mktemp -d)
server_pid="" nginx_conf=""
cleanup() {
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  [ -n "$nginx_conf" ] && nginx -c "$nginx_conf" -s stop 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

token=$(head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n')
export CYCLONEDDS_URI='<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface address="127.0.0.1" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'
SCANPLAN_OPERATOR_TOKEN=$token "$build/server/scanplan-server" --session "$work/session" \
  --listen 127.0.0.1:0 --domain 202 --web "$src/web/dist" >"$work/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 100); do
  url=$(grep -o 'listening on http://[0-9.:]*' "$work/server.log" | sed 's/listening on //' || true)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || { cat "$work/server.log" >&2; exit 1; }
"$build/server/scanplan" replay "$src/samples/replays/campus/campus.replay.json" --server "$url" \
  --token "$token" >/dev/null 2>&1
curl -sf -H "Authorization: Bearer $token" "$url/api/v1/session" >"$work/session.json"
size=$(stat -c %s "$work/session.json")

# nginx as it is usually deployed for static files, one worker per core.
mkdir -p "$work/www" "$work/nginx"
cp "$work/session.json" "$work/www/session.json"
nginx_conf="$work/nginx/nginx.conf"
cat >"$nginx_conf" <<EOF
worker_processes auto;
pid $work/nginx/nginx.pid;
error_log $work/nginx/error.log;
events { worker_connections 1024; }
http {
  access_log off;
  sendfile on;
  keepalive_requests 1000000;
  client_body_temp_path $work/nginx;
  proxy_temp_path $work/nginx;
  fastcgi_temp_path $work/nginx;
  uwsgi_temp_path $work/nginx;
  scgi_temp_path $work/nginx;
  server {
    listen 127.0.0.1:18089;
    root $work/www;
    default_type application/json;
  }
}
EOF
nginx -c "$nginx_conf"
sleep 0.5

rps() { awk '/Requests\/sec/ {print $2}'; }
ours=$(wrk -t2 -c64 -d"${seconds}s" -H "Authorization: Bearer $token" "$url/api/v1/session" | rps)
theirs=$(wrk -t2 -c64 -d"${seconds}s" "http://127.0.0.1:18089/session.json" | rps)
ratio=$(awk -v a="$ours" -v b="$theirs" 'BEGIN {printf "%.3f", a / b}')
printf '{"bench":"http_session_vs_nginx","body_bytes":%s,"seconds":%s,"wrk":"-t2 -c64","rps_scanplan":%s,"rps_nginx":%s,"ratio":%s,"nginx":"%s"}\n' \
  "$size" "$seconds" "$ours" "$theirs" "$ratio" "$(nginx -v 2>&1 | sed 's/.*nginx\///')"
