#!/usr/bin/env bash
# mesh_downloads.sh - the daemon's memory while it serves a large mesh: a job of about
# 1.1 million triangles (the fixed case, offset cells, element size a quarter of the
# radius) is run once, then each mesh format (msh, inp, vtu) is downloaded alone: the
# daemon's RSS before, its peak during the download (VmHWM, reset before each), and after;
# then CONCURRENT downloads at once (the three formats in turn, every other one gzip).
# Prints markdown. Not a test: run by hand (bench/MESH.md and bench/SERVICE.md have the
# figures). GP_DAEMON=path runs another grainpackd (an older build, to compare).
# Usage: bash bench/mesh_downloads.sh
set -euo pipefail
cd "$(dirname "$0")/.."
concurrent=${GP_CONCURRENT:-6}
source bench/daemon.sh --max-elements 3000000

spec='{"inputs": {"domain": {"width": 100, "height": 100},
  "distribution": {"kind": "constant", "radius": 0.9}, "joint": {"law": "constant", "value": 0.1},
  "seed": 1, "laguerre": {"shrink": "offset"}, "mesh": {"element_size": 0.225}}}'
job=$(curl -s -o /dev/null -w '%header{location}' -H 'Content-Type: application/json' -d "$spec" \
  "$base/processes/pack2d/execution")
until curl -s "$base$job?wait=60" | grep -qE '"status":"(successful|failed|dismissed)"'; do :; done
curl -s "$base$job" | grep -q '"status":"successful"' || { echo "the job failed"; exit 1; }
sleep 1  # the worker's trim of malloc's arenas, once the job is stored
counts=$(curl -s "$base$job/statistics" | python3 -c "
import json, sys
m = json.load(sys.stdin)['mesh']
print(m['nodes'], m['elements']['triangles'], m['elements']['quadrilaterals'])")
read -r nodes tri quad <<< "$counts"

download_rows "$base$job/results" msh inp vtu

if [ "$concurrent" -gt 0 ]; then concurrent_downloads "$concurrent" "$base$job/results" "msh, inp, vtu in turn" msh inp vtu; fi
echo
echo "job: $nodes nodes, $tri triangles, $quad quadrilaterals; daemon $GP_DAEMON"
echo "load average $load_start at the start, $(cut -d' ' -f1 /proc/loadavg) at the end;" \
  "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
