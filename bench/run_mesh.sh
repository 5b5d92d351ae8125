#!/usr/bin/env bash
# run_mesh.sh - builds grainpack in Release in build-bench/ and runs the mesh stage's
# benchmark beside Gmsh, printing markdown (bench/MESH.md holds the latest run).
# Arguments go to the benchmark (--quick, --no-gmsh, --no-gmsh-large).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build-bench -j"$(nproc)" --target grainpack_mesh_bench > /dev/null
./build-bench/bench/grainpack_mesh_bench "$@" examples
