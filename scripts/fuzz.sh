#!/usr/bin/env bash
# Builds the libFuzzer target with clang and fuzzes the surface readers and validation for a
# bounded time. New crashing inputs land in build-fuzz/findings; copy a reduced one into
# tests/fuzz/corpus (with the fix) so the fuzz_regression unit test keeps replaying it.
# Usage: fuzz.sh [SECONDS] [JOBS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
jobs=${2:-1}
command -v clang++ > /dev/null || { sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo; $sudo apt-get install -y -qq clang libclang-rt-14-dev; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARTET_FUZZ=ON \
  -DPARTET_BUILD_TESTS=OFF > /dev/null
cmake --build build-fuzz --target fuzz_surface_reader -j 2
mkdir -p build-fuzz/corpus build-fuzz/findings
cp -n tests/fuzz/corpus/* build-fuzz/corpus/ 2>/dev/null || true
./build-fuzz/fuzz_surface_reader build-fuzz/corpus -max_total_time="$seconds" -rss_limit_mb=4096 -timeout=20 \
  -max_len=4096 -jobs="$jobs" -workers="$jobs" -artifact_prefix=build-fuzz/findings/ -print_final_stats=1
