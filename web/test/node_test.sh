#!/bin/bash
# Runs one of the web player's node tests for ctest (web.conformance, web.streaming, web.page,
# web.xr, web.match, web.match_raster, web.av1).
# Skipped (77, one line) without node, build/npm's packages or a further TOOL (a command, or
# npm:PACKAGE), failed instead with CI=true (tools/setup.sh installs them all). With chromium
# among the TOOLs, the script gets its path as its argument.
#   web/test/node_test.sh SOURCE_DIR NAME SCRIPT.mjs [TOOL...]
set -eu
src=$1
name=$2
script=$3
shift 3
. "$src/tests/cli/require_tools.sh"
require_tools "$name" "$src/build/npm" node npm:hash-wasm npm:fzstd npm:xz-decompress "$@"
args=()
for tool in "$@"; do
  if [ "$tool" = chromium ]; then args+=("$(command -v chromium)"); fi
done
exec node "$src/web/test/$script" "${args[@]}"
