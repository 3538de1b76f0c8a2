#!/usr/bin/env bash
# The README's demo command: installs what is missing, builds in Release and runs the end-to-end
# pipeline on a built-in sample: ray-trace a capture set of the animated `interior` scene, encode
# it into a .calf clip, summarise and fully verify the clip, render ground truth along the scene's
# eye path and play the clip headless along it (GL through OSMesa), comparing every frame with the
# ground truth. A second run skips installed packages and rebuilds incrementally. (The one-screen
# report and the contact sheet are issue 9's.)
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
BUILD=build/release
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" --target calf-capture calf-encode calf-info calf-verify calf-play
OUT=build/demo
rm -rf "$OUT"
mkdir -p "$OUT"
echo "== calf-capture: interior scene, 9 viewpoints, 6 x 64^2 faces, 8 frames"
"$BUILD"/calf-capture --scene interior --out "$OUT/capture" --face-size 64 --frames 8
echo "== calf-encode: BC6H colour (the scene is HDR), raw16 depth, zstd"
"$BUILD"/calf-encode "$OUT/capture/manifest.json" -o "$OUT/interior.calf"
echo "== calf-info"
"$BUILD"/calf-info "$OUT/interior.calf"
echo "== calf-verify"
"$BUILD"/calf-verify "$OUT/interior.calf"
echo "== calf-capture --ground-truth: 8 poses along the scene's eye path, 128 x 128"
"$BUILD"/calf-capture --scene interior --ground-truth --out "$OUT/ground-truth" --frames 8 \
  --gt-size 128x128
echo "== calf-play --headless: the clip along that path, compared with the ground truth"
"$BUILD"/calf-play "$OUT/interior.calf" --headless --compare "$OUT/ground-truth" --out "$OUT/play"
echo "demo: capture set in $OUT/capture, clip in $OUT/interior.calf, frames and error heat maps" \
  "in $OUT/play"
