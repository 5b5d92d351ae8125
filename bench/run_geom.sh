#!/usr/bin/env bash
# run_geom.sh - builds grainpack in Release in build-bench/ and runs the geometry stages'
# benchmark, printing markdown tables (bench/GEOM_RESULTS.md holds the latest run).
# Arguments go to the benchmark (--quick, --grains N).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpack_geom_bench > /dev/null
./build-bench/bench/grainpack_geom_bench "$@" examples
