#!/usr/bin/env bash
# The tiles export in a real client (ctest cli.calf_export_tiles_three): the play fixture's tiles
# clip exported with calf-export's defaults, rendered by three.js in headless Chromium at 5 poses
# inside the view region, each compared with calf-play's headless frame of the same pose
# (tests/export/three_compare.js): every pose must reach MIN_DB.
# Usage: three_compare.sh BIN_DIR SOURCE_DIR PLAY_DIR WORK_DIR MIN_DB
# Without Chromium, node or build/npm's three / playwright-core it is skipped (exit 77, one line),
# except with CI=true, where it fails.
set -euo pipefail
bin=$1 src=$2 play=$3 work=$4 min_db=$5
npm_dir="$src/build/npm"
missing=()
chromium="$(command -v chromium || true)"
[ -n "$chromium" ] || missing+=(chromium)
command -v node >/dev/null || missing+=(node)
for p in three playwright-core; do
  [ -f "$npm_dir/node_modules/$p/package.json" ] || missing+=("npm:$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "${CI:-}" = "true" ]; then
    echo "three_compare: FAILED: ${missing[*]} missing with CI=true (tools/setup.sh installs them)"
    exit 1
  fi
  echo "three_compare: skipped: ${missing[*]} missing (tools/setup.sh installs them)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
node "$src/tests/export/three_compare.js" poses "$play/cap/manifest.json" "$work/eye_path.json" 160 120
"$bin/calf-export" "$play/tiles.calf" -o "$work/tiles.glb"
"$bin/calf-play" "$play/tiles.calf" --headless --eye-path "$work/eye_path.json" --out "$work/frames" \
  >/dev/null
node "$src/tests/export/three_compare.js" compare "$npm_dir" "$chromium" "$work/tiles.glb" \
  "$work/eye_path.json" "$work/frames" "$min_db"
