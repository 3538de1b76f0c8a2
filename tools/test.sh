#!/usr/bin/env bash
# The README's test command: installs what is missing, builds every target with
# AddressSanitizer + UndefinedBehaviorSanitizer and warnings as errors, runs every test via ctest.
# A second run skips installed packages and rebuilds incrementally.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
BUILD=build/asan
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O2 -g1" \
  -DCALF_SANITIZE=ON -DCALF_WERROR=ON >/dev/null
cmake --build "$BUILD"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp"
ctest --test-dir "$BUILD" --output-on-failure -j"$(nproc)" "$@"
