#!/usr/bin/env bash
# load.sh - grainpackd under a mixed load, as a department would give it: 200 connections
# for SECONDS (default 60) -- 40 submitting jobs, 100 polling job statuses, 60 downloading
# results as CSV -- with an API key, while the queue keeps both workers busy (the queue
# cap, --max-queued 2000, is reached: those 503s are deliberate). Run RUNS times (default
# 2) on the same daemon. Prints per endpoint requests, p50/p99 latency and answers by
# status; whether every job answered 201 is in the database (none lost), the outcome of
# every job once the queue is drained (all successful), how busy the workers were (the
# health sampled every second) and the daemon's resident memory before and after each run. Builds Release in build-bench/. Not a test.
# Usage: bash bench/load.sh [SECONDS] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
runs=${2:-2}
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpackd > /dev/null
dir=$(mktemp -d)
key=$(head -c 32 /dev/urandom | base64 | tr '+/' '-_' | tr -d '=')
echo "sha256:$(printf %s "$key" | sha256sum | cut -d' ' -f1) bench user" > "$dir/keys"
# every connection comes from 127.0.0.1: the per-address limit is raised for the bench
./build-bench/server/grainpackd --port 0 --data-dir "$dir" --ready-file "$dir/port" \
  --key-file "$dir/keys" --max-queued 2000 --max-jobs-per-key 100000 \
  --max-connections-per-ip 1000 --max-disks 10000000 2> "$dir/log" &
pid=$!
trap 'kill "$pid" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT
while [ ! -s "$dir/port" ]; do sleep 0.05; done
base="http://127.0.0.1:$(cat "$dir/port")"
api() { curl -sf -H "Authorization: Bearer $key" "$@"; }
field() { python3 -c "import json,sys; print(json.load(sys.stdin)['$1'])"; }
rss() { awk '/VmRSS/ {print $2 / 1024 " MB"}' "/proc/$pid/status"; }
jobs() { sqlite3 "$dir/grainpack.db" "select count(*) from jobs $1"; }
drain() {
  while [ "$(curl -sf "$base/health" | field queue_depth)" != 0 ] ||
        [ "$(curl -sf "$base/health" | field workers_busy)" != 0 ]; do sleep 0.2; done
}

# what is downloaded and polled: 50 finished iron jobs (about 1000 disks, a 70 KB CSV)
for _ in $(seq 50); do
  api -H 'Content-Type: application/json' --data-binary @examples/iron.json \
    "$base/processes/pack2d/execution" | field jobID >> "$dir/ids"
done
drain
# what is submitted: about 28000 disks, some 30 ms of packing each, so that the 40
# submitting connections outrun the two workers and the queue fills up
echo '{"inputs": {"domain": {"width": 300, "height": 300}, "distribution": {"kind": "constant", "radius": 1.0}}}' \
  > "$dir/medium.json"
# the machine's other users, sampled every second (they take processor time from the run)
( while sleep 1; do
    ps -eo pcpu=,comm= | awk '$1 > 20 && $2 !~ /^(grainpackd|MHD-worker|wrk|curl|python3|ps|awk|sqlite3)$/ {print $2}'
  done > "$dir/others" ) &
sampler=$!
trap 'kill "$pid" "$sampler" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT

load() { # mode connections output
  GP_LOAD_MODE=$1 GP_KEY=$key GP_IDS=$dir/ids GP_SPEC=$dir/medium.json GP_ACCEPTED=$3.ids \
    wrk -t1 -c"$2" -d"${seconds}s" --timeout 30s --latency -s bench/load.lua "$base" > "$3"
}
p() { awk -v q="$2" '$1 == q {print $2}' "$1"; }
statuses() { awk '$1 == "status" {printf "%s%s: %s", sep, $2, $3; sep=", "}' "$1"; }
count() { awk -v s="$2" '$1 == "status" && $2 == s {print $3}' "$1"; }

echo "grainpackd $(git describe --always --dirty), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
before_all=$(rss)
for run in $(seq "$runs"); do
  rows_before=$(jobs "")
  rss_before=$(rss)
  load submit 40 "$dir/submit.txt" &
  loads=$!
  load poll 100 "$dir/poll.txt" &
  loads="$loads $!"
  load fetch 60 "$dir/fetch.txt" &
  loads="$loads $!"
  : > "$dir/busy"
  for _ in $(seq $((seconds - 1))); do
    sleep 1
    curl -sf "$base/health" | field workers_busy >> "$dir/busy"
  done
  # shellcheck disable=SC2086
  wait $loads
  accepted=$(count "$dir/submit.txt" 201)
  rows=$(( $(jobs "") - rows_before ))
  sqlite3 "$dir/grainpack.db" "select id from jobs" | sort > "$dir/rows"
  lost=$(sort "$dir/submit.txt.ids" | comm -23 - "$dir/rows" | wc -l)
  drain
  unsuccessful=$(jobs "where status != 'successful'")
  echo "Run $run ($seconds s, 200 connections):"
  echo
  echo "| endpoint | connections | requests | p50 | p99 | answers by status |"
  echo "| --- | --- | --- | --- | --- | --- |"
  for e in "POST /processes/pack2d/execution:40:submit" "GET /jobs/{id}:100:poll" "GET /jobs/{id}/results?f=csv:60:fetch"; do
    IFS=: read -r name conns file <<< "$e"
    echo "| $name | $conns | $(awk '/requests in/ {print $1}' "$dir/$file.txt") | $(p "$dir/$file.txt" 50%) | $(p "$dir/$file.txt" 99%) | $(statuses "$dir/$file.txt") |"
  done
  echo
  echo "- workers busy, sampled every second: $(sort "$dir/busy" | uniq -c | awk '{printf "%s%s of 2 in %s samples", sep, $2, $1; sep=", "}')"
  echo "- jobs answered 201: $accepted, of them missing from the database: $lost; rows the database gained: $rows (the difference: submissions in flight when wrk stopped); jobs not successful once the queue drained: $unsuccessful"
  echo "- 5xx other than 503: $(cat "$dir"/{submit,poll,fetch}.txt | awk '$1 == "status" && $2 >= 500 && $2 != 503 {n += $3} END {print n + 0}'); socket errors: $(cat "$dir"/{submit,poll,fetch}.txt | awk '/Socket errors/ {sub(/.*Socket errors: /, ""); print}' | paste -sd';' - | grep . || echo none)"
  echo "- daemon resident memory: $rss_before before, $(rss) after (the queue drained)"
  echo
done
kill "$sampler" 2> /dev/null
others=$(sort "$dir/others" | uniq -c | sort -rn | awk '{printf "%s%s (%s s)", sep, $2, $1; sep=", "}')
echo "Resident memory after the warm-up: $before_all; other processes over 20% of a core during the runs: ${others:-none}"
