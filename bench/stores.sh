#!/usr/bin/env bash
# stores.sh - runs bench/stores.py (sqlite against PostgreSQL with 1, 2 and 3 nodes, and a
# dead node's takeover) on a Release build in build-bench/ and a private PostgreSQL server
# started for it (tests/pg/pg_server.sh, with fsync on as in production), and prints its
# table with the load average before and after. Not a test: run by hand.
# Usage: bash bench/stores.sh [JOBS]   (iron jobs per configuration, default 1000);
# GP_BUILD_DIR: a Release build to use instead (not rebuilt)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${GP_BUILD_DIR:-build-bench}
if [ -z "${GP_BUILD_DIR:-}" ]; then
  cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build build-bench -j"$(nproc)" --target grainpackd > /dev/null
fi
state=$(mktemp)
trap 'tests/pg/pg_server.sh stop "$state"; rm -f "$state"' EXIT
GP_PG_FSYNC=on tests/pg/pg_server.sh start "$state"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
PGPASSWORD=${GP_TEST_PG_PASSWORD:-grainpack-test-password} \
  python3 bench/stores.py "$build/server/grainpackd" "$state" "${1:-1000}"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
