#!/bin/bash
# Runs one of the web player's node tests for ctest (web.conformance, web.streaming). Skipped
# (77, one line) without node or build/npm's packages, failed instead with CI=true
# (tools/setup.sh installs them).
#   web/test/node_test.sh SOURCE_DIR NAME SCRIPT.mjs
set -eu
src=$1
name=$2
. "$src/tests/cli/require_tools.sh"
require_tools "$name" "$src/build/npm" node npm:hash-wasm npm:fzstd npm:xz-decompress
exec node "$src/web/test/$3"
