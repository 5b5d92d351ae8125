#!/usr/bin/env bash
# end_to_end.sh - the command line from process start to file written, per format (issue
# 12's acceptance): `grainpack run SPEC -f FORMAT -o FILE` on the report's four cases and on
# the Bagi law scaled to about 10^6 disks, timed by hyperfine (Debian's `hyperfine`), one
# process at a time. Prints markdown: median wall time and mean user CPU per case and format, and
# disks per second for the 10^6 row. Not a test: run by hand on a quiet machine
# (bench/RESULTS.md has the figures).
# Usage: bash bench/end_to_end.sh [RUNS]   (RUNS for the four cases, default 20; the 10^6
# row runs 3 times). GP_CLI=path times another grainpack.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-20}
if [ -z "${GP_CLI:-}" ]; then
  cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build build-bench -j"$(nproc)" --target grainpack > /dev/null
  GP_CLI=./build-bench/cli/grainpack
fi
command -v hyperfine > /dev/null || { echo "end_to_end.sh: needs hyperfine (apt-get install hyperfine)" >&2; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
load_start=$(cut -d' ' -f1 /proc/loadavg)

# the Bagi law on 500 x 500: about 1.02 million disks
sed 's/"width": 100, "height": 100/"width": 500, "height": 500/' examples/bagi.json > "$dir/bagi1m.json"

# median wall ms and mean user CPU ms of `grainpack run SPEC -f FORMAT`, from hyperfine's JSON export
time_run() {
  local spec=$1 fmt=$2 n=$3
  hyperfine -N -w 1 -r "$n" --export-json "$dir/t.json" \
    "$GP_CLI run $spec -f $fmt -o $dir/out.$fmt" > /dev/null 2>&1
  python3 -c "
import json
r = json.load(open('$dir/t.json'))['results'][0]
print(f'{1e3 * r[\"median\"]:.1f} {1e3 * r[\"user\"]:.1f}')"
}

echo "| case | disks | csv | json | svg | vtk |"
echo "| --- | --- | --- | --- | --- | --- |"
for name in fixed variable iron bagi bagi1m; do
  spec=examples/$name.json n=$runs
  [ "$name" = bagi1m ] && spec=$dir/bagi1m.json n=3
  "$GP_CLI" run "$spec" -f csv -o "$dir/count.csv"
  disks=$(($(wc -l < "$dir/count.csv") - 1))
  row="| $name | $disks |"
  for fmt in csv json svg vtk; do
    read -r wall user <<< "$(time_run "$spec" "$fmt" "$n")"
    cell="$wall ms (user $user)"
    [ "$name" = bagi1m ] && cell="$cell, $(python3 -c "print(f'{$disks / $wall / 1e3:.2f}')") M/s"
    row="$row $cell |"
  done
  echo "$row"
done
echo
echo "Wall: median over the runs (hyperfine -N, one warm-up); user: mean user CPU a run."
echo "load average $load_start at the start, $(cut -d' ' -f1 /proc/loadavg) at the end;" \
  "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $GP_CLI"
