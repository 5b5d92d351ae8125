#!/usr/bin/env bash
# service.sh - benchmarks grainpackd end to end on this machine and prints a markdown
# table: iron jobs per second with every worker busy (wrk submitting as fast as it can,
# then the time until the queue is drained), and GET /jobs/{id} latency at 100
# connections while jobs run. Builds Release in build-bench/. Not a test: run by hand.
# Usage: bash bench/service.sh [SECONDS]   (each phase runs that long, default 10)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-10}
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpackd > /dev/null
dir=$(mktemp -d)
trap 'kill "$pid" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT
./build-bench/server/grainpackd --port 0 --data-dir "$dir" --ready-file "$dir/port" \
  --max-queued 10000000 --max-disks 10000000 2> "$dir/log" &
pid=$!
while [ ! -s "$dir/port" ]; do sleep 0.05; done
base="http://127.0.0.1:$(cat "$dir/port")"
health() { curl -sf "$base/health" | python3 -c "import json,sys; h=json.load(sys.stdin); print(h['$1'])"; }
count() { curl -sf "$base/metrics" | awk -v k="grainpack_jobs{status=\"$1\"}" '$1 == k {print $2}'; }

# 1. throughput: submit iron jobs for $seconds s, then wait for the queue to drain
start=$(date +%s.%N)
GP_SPEC=examples/iron.json wrk -t2 -c8 -d"${seconds}s" -s bench/submit.lua \
  "$base/processes/pack2d/execution" > "$dir/submit.txt"
while [ "$(health queue_depth)" != 0 ] || [ "$(health workers_busy)" != 0 ]; do sleep 0.05; done
end=$(date +%s.%N)
done_jobs=$(count successful)
submitted=$(awk '/requests in/ {print $1}' "$dir/submit.txt")
rejected=$(awk '/Non-2xx/ {print $NF}' "$dir/submit.txt")
throughput=$(python3 -c "print(f'{$done_jobs / ($end - $start):.0f}')")

# 2. latency of GET /jobs/{id} at 100 connections while the workers pack: a batch of
# larger jobs (about 1 s each, 1.5 times the work the workers can do in the window)
# keeps every worker busy through the whole measurement
mid='{"inputs": {"domain": {"width": 1500, "height": 1500}, "distribution": {"kind": "constant", "radius": 1.0}}}'
for _ in $(seq $((seconds * $(nproc) * 3 / 2))); do
  curl -sf -o /dev/null -H 'Content-Type: application/json' -d "$mid" "$base/processes/pack2d/execution"
done
job=$(curl -sf "$base/jobs?limit=1&status=successful" | python3 -c "import json,sys; print(json.load(sys.stdin)['jobs'][0]['jobID'])")
wrk -t2 -c100 -d"${seconds}s" --latency "$base/jobs/$job" > "$dir/get.txt"
busy=$(health workers_busy)
queued=$(health queue_depth)
p50=$(awk '$1 == "50%" {print $2}' "$dir/get.txt")
p99=$(awk '$1 == "99%" {print $2}' "$dir/get.txt")
rps=$(awk '/Requests\/sec/ {print $2}' "$dir/get.txt")

echo "| measure | value |"
echo "| --- | --- |"
echo "| iron jobs submitted in ${seconds} s (wrk, 8 connections) | $submitted (${rejected:-0} refused) |"
echo "| iron jobs completed per second, submit to last result stored | $throughput |"
echo "| GET /jobs/{id} at 100 connections: requests/s | $rps |"
echo "| GET /jobs/{id} latency p50 / p99 | $p50 / $p99 |"
echo "| workers busy / jobs queued at the end of the latency run | $busy / $queued |"
echo
echo "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
