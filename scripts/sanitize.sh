#!/usr/bin/env bash
# Builds partet with AddressSanitizer + UBSan (build-asan) and runs the unit, CLI and MPI tests
# under it. Leaks of TetGen's error path and of OpenMPI are suppressed (tests/sanitizer/lsan.supp).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARTET_SANITIZE=ON > /dev/null
cmake --build build-asan -j "${PARTET_JOBS:-2}"
source scripts/common.sh
export OMPI_MCA_rmaps_base_oversubscribe=1
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizer/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Unit tests (no MPI): memory errors, undefined behaviour and leaks.
ASAN_OPTIONS="detect_leaks=1" ctest --test-dir build-asan -L unit -j 2 --output-on-failure
# Whole program runs: OpenMPI's dlopen'ed components leak at MPI_Init and show up without a
# module name, so leak detection is off there (memory errors and UB are still fatal).
ASAN_OPTIONS="detect_leaks=0" ctest --test-dir build-asan -L "cli|mpi" -j 2 --output-on-failure
