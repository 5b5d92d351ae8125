#!/usr/bin/env bash
# kill_restart.sh - runs the SIGKILL-under-load test (tests/service/test_service_crash.py,
# three kills and restarts per run) N times in a row (default 20) against the build in
# build/, and prints one line per run and a summary: any accepted job lost, any
# half-written result, any integrity_check failure fails the run. Not a test: by hand.
# Usage: bash bench/kill_restart.sh [N]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-20}
cmake -S . -B build > /dev/null
cmake --build build -j"$(nproc)" --target grainpackd > /dev/null
passed=0
jobs=0
for i in $(seq "$n"); do
  if out=$(python3 tests/service/test_service_crash.py build/server/grainpackd 2>&1); then
    passed=$((passed + 1))
    got=$(echo "$out" | awk '/accepted jobs over/ {print $1}')
    jobs=$((jobs + got))
    echo "run $i: ok, $(echo "$out" | grep 'accepted jobs over' | sed 's/^ *//')"
  else
    echo "run $i: FAILED"
    echo "$out" | grep -E "FAIL|Error" | head -5
  fi
done
echo "$passed of $n runs passed; $jobs accepted jobs over $((3 * n)) kills"
