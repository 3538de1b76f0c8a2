#!/usr/bin/env bash
# The tiles OBJ in Blender (ctest cli.calf_export_tiles_blender): the play fixture's tiles clip
# exported with calf-export's defaults as .obj (+ .mtl + atlas with map_d) and as .glb; Blender 3.4
# imports the .obj and renders it unlit with Cycles (tests/export/blender_obj_render.py), three.js
# in headless Chromium renders the .glb (tests/export/three_compare.js), both at the 5 poses of
# cli.calf_export_tiles_three, each compared with calf-play's frame of the pose. Blender's mean
# PSNR over the poses must be at least the .glb's minus MAX_LOSS_DB, and every pose's at least the
# .glb's minus twice that.
# Usage: blender_compare.sh BIN_DIR SOURCE_DIR MANIFEST.json CLIP WORK_DIR MAX_LOSS_DB
# Without Blender, Chromium, node or build/npm's three / playwright-core it is skipped (exit 77,
# one line), except with CI=true, where it fails.
set -euo pipefail
bin=$1 src=$2 manifest=$3 clip=$4 work=$5 max_loss=$6
npm_dir="$src/build/npm"
. "$src/tests/cli/require_tools.sh"
require_tools blender_compare "$npm_dir" blender chromium node npm:three npm:playwright-core
chromium="$(command -v chromium)"
rm -rf "$work"
mkdir -p "$work"
node "$src/tests/export/three_compare.js" poses "$manifest" "$work/eye_path.json" 160 120
"$bin/calf-export" "$clip" -o "$work/tiles.glb"
"$bin/calf-export" "$clip" -o "$work/tiles.obj"
"$bin/calf-play" "$clip" --headless --eye-path "$work/eye_path.json" --out "$work/frames" >/dev/null
CALF_THREE_JSON="$work/three.json" node "$src/tests/export/three_compare.js" compare "$npm_dir" \
  "$chromium" "$work/tiles.glb" "$work/eye_path.json" "$work/frames" 0 >/dev/null
started=$(date +%s)
blender -b --factory-startup -noaudio -P "$src/tests/export/blender_obj_render.py" -- \
  "$work/tiles.obj" "$work/eye_path.json" "$work/frames" "$work" >"$work/blender.log" 2>&1 ||
  { tail -20 "$work/blender.log"; echo "blender_compare: FAILED: Blender failed"; exit 1; }
seconds=$(($(date +%s) - started))
# Each pose: Blender's PSNR (OBJ) beside three.js's (.glb), both against calf-play. The OBJ's mean
# over the poses may lie at most MAX_LOSS dB below the .glb's, and no pose more than twice that:
# Cycles orders nearly coplanar tiles per pixel by depth where calf-play and three.js draw whole
# tiles in the file's order, which moves a single pose by up to about 2 dB either way; a file
# that loses its alpha (no map_d) loses 15-25 dB at every pose.
node - "$work/blender.log" "$work/three.json" "$max_loss" "$seconds" <<'JS'
const fs = require('fs');
const [log, threeFile, maxLoss, seconds] = process.argv.slice(2);
const three = JSON.parse(fs.readFileSync(threeFile, 'utf8'));
const blender = [...fs.readFileSync(log, 'utf8').matchAll(/^pose (\d+): PSNR ([0-9.]+) dB$/gm)]
    .map((m) => Number(m[2]));
let ok = blender.length === three.length && blender.length > 0, worst = Infinity;
let sumBlender = 0, sumThree = 0;
blender.forEach((b, i) => {
  const loss = three[i].psnr - b;
  worst = Math.min(worst, -loss);
  sumBlender += b;
  sumThree += three[i].psnr;
  console.log(`pose ${i}: OBJ in Blender ${b.toFixed(2)} dB, .glb in three.js ` +
              `${three[i].psnr.toFixed(2)} dB (linear blending ${three[i].psnr_linear.toFixed(2)} dB): ` +
              `${loss >= 0 ? loss.toFixed(2) + ' dB below' : (-loss).toFixed(2) + ' dB above'}`);
  if (!(loss <= 2 * Number(maxLoss))) ok = false;
});
const meanLoss = (sumThree - sumBlender) / Math.max(1, blender.length);
if (!(meanLoss <= Number(maxLoss))) ok = false;
console.log(`blender_compare: ${blender.length} poses, OBJ mean ${(sumBlender / blender.length).toFixed(2)} dB ` +
            `against the .glb's ${(sumThree / blender.length).toFixed(2)} dB, worst pose ` +
            `${worst.toFixed(2)} dB (Blender ${seconds} s)`);
if (!ok) {
  console.log(`blender_compare: FAILED: the mean is more than ${maxLoss} dB below the .glb's, ` +
              `or a pose more than ${2 * Number(maxLoss)} dB`);
  process.exit(1);
}
JS
