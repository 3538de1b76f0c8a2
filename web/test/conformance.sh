#!/bin/bash
# ctest's web.conformance: the page decoder under node against every lightfield conformance clip
# (web/test/conformance.mjs). Skipped (77, one line) without node or build/npm's packages,
# failed instead with CI=true (tools/setup.sh installs them).
#   web/test/conformance.sh SOURCE_DIR
set -eu
src=$1
. "$src/tests/cli/require_tools.sh"
require_tools web.conformance "$src/build/npm" node npm:hash-wasm npm:fzstd npm:xz-decompress
exec node "$src/web/test/conformance.mjs"
