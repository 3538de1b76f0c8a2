#!/bin/bash
# Builds calf with the test-only track kind (tests/test_kind/, CMake option CALF_TEST_KIND) in
# build/test-kind and runs what exercises it: its own tests (the decoder and player tables'
# entries, calf-info's and calf-verify's lines), the conformance runner's entries for its clips,
# and the track registry test with the kind registered. Extra arguments go to ctest.
# docs/ARCHITECTURE.md, "The test-only kind".
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/test-kind
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0 \
  -DCALF_WERROR=ON -DCALF_TEST_KIND=ON "${launcher[@]}" >/dev/null
cmake --build "$build" -j"${CALF_JOBS:-2}" --target calf-info calf-verify swatch_kind_test track_registry_test
ctest --test-dir "$build" -R 'swatch|track_registry' --output-on-failure "$@"
