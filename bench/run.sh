#!/usr/bin/env bash
# run.sh - builds grainpack in Release in build-bench/ and runs the benchmark, printing
# markdown tables. Arguments go to the benchmark (--quick, --max-disks N).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpack_bench > /dev/null
./build-bench/bench/grainpack_bench "$@" examples
