#!/usr/bin/env bash
# downloads.sh - how grainpackd serves a large result: a 10^6-grain job (the Bagi law on
# 506 x 506, two sweeps of relocation, offset Laguerre cells) is run once, then each
# format is downloaded: time to first byte and total (median of RUNS), size, gzip size
# and time, and the daemon's peak RSS while CONCURRENT downloads run at once (a quarter
# per format, every other one gzip), against its idle RSS. Prints markdown. Not a test:
# run by hand (bench/SERVICE.md has the figures).
# Usage: bash bench/downloads.sh [SIDE]   (SIDE 506: about 950 000 grains)
# GP_DAEMON=path runs another grainpackd (an older build, to compare); GP_CONCURRENT=0
# skips the concurrent downloads (for a build that renders each download in memory).
set -euo pipefail
cd "$(dirname "$0")/.."
side=${1:-506}
runs=${RUNS:-3}
concurrent=${GP_CONCURRENT:-20}
source bench/daemon.sh --max-disks 3000000

spec="{\"inputs\": {\"domain\": {\"width\": $side, \"height\": $side},
  \"distribution\": {\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42},
  \"balance\": {\"method\": \"relocation\", \"max_iterations\": 2},
  \"laguerre\": {\"shrink\": \"offset\"}, \"picture\": {\"color\": \"quality\"}}}"
t0=$(date +%s.%N)
job=$(curl -s -o /dev/null -w '%header{location}' -H 'Content-Type: application/json' -d "$spec" \
  "$base/processes/pack2d/execution")
until curl -s "$base$job?wait=60" | grep -qE '"status":"(successful|failed|dismissed)"'; do :; done
t1=$(date +%s.%N)
sleep 1  # the worker's trim of malloc's arenas, once the job is stored
after_job=$(rss VmRSS)
curl -s "$base$job" | grep -q '"status":"successful"' || { echo "the job failed"; exit 1; }
grains=$(curl -s "$base$job/statistics" | python3 -c "import json,sys; print(json.load(sys.stdin)['count'])")
runs_before=$(curl -s "$base/metrics" | awk '$1 == "grainpack_pipeline_runs_total" {print $2}')

median() { sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }
# one download: "ttfb total bytes" (curl's own clock)
fetch() { curl -s -o /dev/null -w '%{time_starttransfer} %{time_total} %{size_download}\n' "$@"; }

echo "| format | bytes | first byte | total | MB/s | gzip bytes (ratio) | gzip first byte | gzip total |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for fmt in csv json svg vtk; do
  url="$base$job/results?f=$fmt"
  plain=$(for _ in $(seq "$runs"); do fetch "$url"; done)
  packed=$(for _ in $(seq "$runs"); do fetch -H 'Accept-Encoding: gzip' "$url"; done)
  ttfb=$(awk '{print $1}' <<< "$plain" | median)
  total=$(awk '{print $2}' <<< "$plain" | median)
  bytes=$(awk 'NR == 1 {print $3}' <<< "$plain")
  gz_ttfb=$(awk '{print $1}' <<< "$packed" | median)
  gz_total=$(awk '{print $2}' <<< "$packed" | median)
  gz_bytes=$(awk 'NR == 1 {print $3}' <<< "$packed")
  python3 -c "
b, gb = $bytes, $gz_bytes
print(f'| {\"$fmt\"} | {b / 1e6:.1f} MB | {1e3 * $ttfb:.1f} ms | {$total:.3f} s | {b / 1e6 / $total:.0f} |'
      f' {gb / 1e6:.1f} MB ({gb / b:.3f}) | {1e3 * $gz_ttfb:.1f} ms | {$gz_total:.3f} s |')"
done

if [ "$concurrent" -gt 0 ]; then concurrent_downloads "$concurrent" "$base$job/results" "every format" csv json svg vtk; fi
runs_after=$(curl -s "$base/metrics" | awk '$1 == "grainpack_pipeline_runs_total" {print $2}')
echo
python3 -c "print(f'job: {$grains} grains, {$t1 - $t0:.1f} s from submission to successful;'
                  f' daemon RSS {$after_job / 1024:.1f} MB idle once it was stored;'
                  f' pipeline runs {${runs_before:-0}} before the downloads, {${runs_after:-0}} after')"
echo "load average $load_start at the start, $(cut -d' ' -f1 /proc/loadavg) at the end;" \
  "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
