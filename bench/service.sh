#!/usr/bin/env bash
# service.sh - benchmarks grainpackd end to end on this machine and prints a markdown
# table: iron jobs per second with every worker busy (wrk submitting as fast as it can,
# then the time until the queue is drained), and GET /jobs/{id} latency at 100
# connections while jobs run. Builds Release in build-bench/. Not a test: run by hand.
# Usage: bash bench/service.sh [SECONDS]   (each phase runs that long, default 10);
# GP_DAEMON_ARGS adds options to the daemon (e.g. "--http-threads 4").
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-10}
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpackd > /dev/null
dir=$(mktemp -d)
trap 'kill "$pid" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT
./build-bench/server/grainpackd --port 0 --data-dir "$dir" --ready-file "$dir/port" \
  --max-queued 10000000 --max-disks 10000000 ${GP_DAEMON_ARGS:-} 2> "$dir/log" &
pid=$!
while [ ! -s "$dir/port" ]; do sleep 0.05; done
base="http://127.0.0.1:$(cat "$dir/port")"
health() { curl -sf "$base/health" | python3 -c "import json,sys; h=json.load(sys.stdin); print(h['$1'])"; }
count() { curl -sf "$base/metrics" | awk -v k="grainpack_jobs{status=\"$1\"," 'index($1, k) == 1 {print $2}'; }

# what else runs on the machine meanwhile (other builds make the latency tail longer):
# the processes, not ours, that used more than a fifth of a core, sampled every second
( while sleep 1; do
    ps -eo pcpu=,comm= | awk '$1 > 20 && $2 !~ /^(grainpackd|MHD-worker|wrk|curl|python3|ps|awk)$/ {print $2}'
  done > "$dir/others" ) &
sampler=$!
trap 'kill "$pid" "$sampler" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT

# 0. latency of GET /jobs/{id} at 100 connections with no job running: the baseline
first=$(curl -sf -H 'Content-Type: application/json' --data-binary @examples/iron.json \
  "$base/processes/pack2d/execution" | python3 -c "import json,sys; print(json.load(sys.stdin)['jobID'])")
curl -sf -o /dev/null "$base/jobs/$first?wait=30"
wrk -t2 -c100 -d"${seconds}s" --latency "$base/jobs/$first" > "$dir/idle.txt"

# 1. throughput: submit iron jobs for $seconds s, then wait for the queue to drain
start=$(date +%s.%N)
GP_SPEC=examples/iron.json wrk -t2 -c8 -d"${seconds}s" -s bench/submit.lua \
  "$base/processes/pack2d/execution" > "$dir/submit.txt"
while [ "$(health queue_depth)" != 0 ] || [ "$(health workers_busy)" != 0 ]; do sleep 0.05; done
end=$(date +%s.%N)
done_jobs=$(($(count successful) - 1))
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
wrk -t2 -c100 -d"${seconds}s" --latency "$base/jobs/$first" > "$dir/get.txt"
busy=$(health workers_busy)
queued=$(health queue_depth)
kill "$sampler" 2> /dev/null
p50() { awk '$1 == "50%" {print $2}' "$1"; }
p99() { awk '$1 == "99%" {print $2}' "$1"; }
rps() { awk '/Requests\/sec/ {printf "%.0f", $2}' "$1"; }
others=$(sort "$dir/others" | uniq -c | sort -rn | awk '{printf "%s%s (%s s)", sep, $2, $1; sep=", "}')

echo "| measure | value |"
echo "| --- | --- |"
echo "| iron jobs submitted in ${seconds} s (wrk, 8 connections) | $submitted (${rejected:-0} refused) |"
echo "| iron jobs completed per second, submit to last result stored | $throughput |"
echo "| GET /jobs/{id}, 100 connections, no job running: requests/s, p50 / p99 | $(rps "$dir/idle.txt"), $(p50 "$dir/idle.txt") / $(p99 "$dir/idle.txt") |"
echo "| GET /jobs/{id}, 100 connections, every worker packing: requests/s, p50 / p99 | $(rps "$dir/get.txt"), $(p50 "$dir/get.txt") / $(p99 "$dir/get.txt") |"
echo "| workers busy / jobs queued at the end of that run | $busy / $queued |"
echo
echo "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); other processes over 20% of a core during the run: ${others:-none}"
