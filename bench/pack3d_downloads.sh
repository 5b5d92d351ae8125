#!/usr/bin/env bash
# pack3d_downloads.sh - what the service stores for a pack3d job with offset polyhedra, and
# the daemon's memory while it serves it: a job of about N spheres (uniform radii 0.4-0.8,
# joint 0.05, offset cells; GP_SPHERES, default 80000; GP_BALANCE=1 balances first) is run
# once; the stored bytes of each section (and per sphere), the stage timings (with "tess",
# the worker's rendering of the .tess), then each format downloaded alone: the daemon's
# RSS before, its peak during the download (VmHWM, reset before each) and after; then 8
# concurrent downloads (vtu, json, svg, tess in turn, half gzip) and the daemon's peak.
# Prints markdown. Not a test: run by hand (docs/3d.md §10 has the figures).
# Usage: bash bench/pack3d_downloads.sh
set -euo pipefail
cd "$(dirname "$0")/.."
spheres=${GP_SPHERES:-80000}
source bench/daemon.sh --max-disks 2000000 --max-job-seconds 3600

# the box's side for about that many spheres: mean packing volume 4/3 pi E[R^3] at the
# density the front reaches (about 0.57 with this law, bench/PACK3D.md)
side=$(python3 -c "
import math
R3 = sum(((0.4 + 0.4 * (k + 0.5) / 1000) + 0.05) ** 3 for k in range(1000)) / 1000
print(round((${spheres} * 4 / 3 * math.pi * R3 / 0.57) ** (1 / 3), 2))")
balance=''
[ "${GP_BALANCE:-0}" = 1 ] && balance='"balance": {"method": "relocation"},'
spec="{\"inputs\": {\"domain\": {\"width\": $side, \"height\": $side, \"depth\": $side},
  \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.8},
  \"joint\": {\"law\": \"constant\", \"value\": 0.05}, \"seed\": 1, $balance
  \"laguerre\": {\"shrink\": \"offset\"}}}"
job=$(curl -s -o /dev/null -w '%header{location}' -H 'Content-Type: application/json' -d "$spec" \
  "$base/processes/pack3d/execution")
until curl -s "$base$job?wait=60" | grep -qE '"status":"(successful|failed|dismissed)"'; do :; done
curl -s "$base$job" | grep -q '"status":"successful"' || { echo "the job failed"; curl -s "$base$job"; exit 1; }
sleep 1  # the worker's trim of malloc's arenas, once the job is stored
count=$(curl -s "$base$job/statistics" | python3 -c "
import json, sys
st = json.load(sys.stdin)
print(st['count'], ' '.join(f\"{t['stage']}={t['seconds']:.2f}s\" for t in st['timings']))")
read -r n timings <<< "$count"

echo "| section | bytes | per sphere |"
echo "| --- | --- | --- |"
sqlite3 -separator ' ' "$dir/grainpack.db" "SELECT tag, bytes FROM result_sections ORDER BY id" |
  while read -r tag bytes; do
    python3 -c "print(f'| $tag | {$bytes:,} | {$bytes / $n:.1f} |')"
  done
total=$(sqlite3 "$dir/grainpack.db" "SELECT sum(bytes) FROM result_sections")
python3 -c "print(f'| all | {$total:,} | {$total / $n:.1f} |')"
echo
download_rows "$base$job/results" csv json vtu svg tess
concurrent_downloads 8 "$base$job/results" "vtu, json, svg, tess in turn" vtu json svg tess
echo
echo "job: $n spheres in a box of side $side; stages $timings; daemon $GP_DAEMON"
echo "load average $load_start at the start, $(cut -d' ' -f1 /proc/loadavg) at the end;" \
  "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
