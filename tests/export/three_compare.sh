#!/usr/bin/env bash
# An export in a real client (ctest cli.calf_export_tiles_three, cli.calf_export_mesh_three): a
# clip's tiles or mesh track exported with calf-export's defaults, and again with --meshopt,
# rendered by three.js in headless Chromium at 5 poses inside the capture set's view region, each
# compared with calf-play's headless frame of the same pose (tests/export/three_compare.js):
# every pose must reach MIN_DB, and the --meshopt file's frames MIN_SAME_DB against the plain
# file's. Prints the per-pose figures, both files' bytes and load times.
# Usage: three_compare.sh BIN_DIR SOURCE_DIR MANIFEST.json CLIP WORK_DIR MIN_DB MIN_SAME_DB
# Without Chromium, node or build/npm's three / playwright-core it is skipped (exit 77, one line),
# except with CI=true, where it fails.
set -euo pipefail
bin=$1 src=$2 manifest=$3 clip=$4 work=$5 min_db=$6 min_same_db=$7
npm_dir="$src/build/npm"
. "$src/tests/cli/require_tools.sh"
require_tools three_compare "$npm_dir" chromium node npm:three npm:playwright-core
chromium="$(command -v chromium)"
rm -rf "$work"
mkdir -p "$work"
node "$src/tests/export/three_compare.js" poses "$manifest" "$work/eye_path.json" 160 120
"$bin/calf-export" "$clip" -o "$work/export.glb"
"$bin/calf-export" "$clip" -o "$work/meshopt.glb" --meshopt
"$bin/calf-play" "$clip" --headless --eye-path "$work/eye_path.json" --out "$work/frames" >/dev/null
node "$src/tests/export/three_compare.js" compare "$npm_dir" "$chromium" "$work/export.glb" \
  "$work/eye_path.json" "$work/frames" "$min_db" "$work/meshopt.glb" "$min_same_db"
