#!/usr/bin/env bash
# run.sh - builds the libFuzzer harnesses with clang (build-fuzz/) and runs each for the
# given number of seconds, starting from the corpus in tests/fuzz/corpus/<name>. New
# interesting inputs go to build-fuzz/corpus-<name>; a crash is written to
# tests/fuzz/crashes/<name>/, where ctest replays it from then on (commit it).
# Usage: tests/fuzz/run.sh SECONDS [NAME...]   (default: every harness)
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:?usage: tests/fuzz/run.sh SECONDS [NAME...]}
shift
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DGP_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DGP_BUILD_BENCH=OFF > /dev/null
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for dir in tests/fuzz/corpus/*/; do names+=("$(basename "$dir")"); done
fi
for name in "${names[@]}"; do
  cmake --build build-fuzz -j"$(nproc)" --target "fuzz_$name" > /dev/null
  mkdir -p "build-fuzz/corpus-$name" "tests/fuzz/crashes/$name"
  echo "== fuzz_$name for $seconds s"
  ASAN_OPTIONS=detect_leaks=1 "build-fuzz/tests/fuzz/fuzz_$name" -max_total_time="$seconds" \
    -print_final_stats=1 -artifact_prefix="tests/fuzz/crashes/$name/" \
    "build-fuzz/corpus-$name" "tests/fuzz/corpus/$name" 2>&1 |
    grep -E "DONE|INITED|stat::|ERROR|SUMMARY|Test unit written" || true
done
