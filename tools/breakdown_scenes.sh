#!/usr/bin/env bash
# The error breakdown (docs/PLAYER.md "Error breakdown") of the built-in scenes at the quick
# setting (128² faces, 128² eye): a converged capture and ground truth, a clip at the encoder's
# defaults and a lossless twin (rgba16f colour), then calf-play --breakdown.
# Usage: tools/breakdown_scenes.sh [BUILD_DIR] [OUT_DIR]; steps whose output exists are skipped.
set -euo pipefail
B=${1:-build/rel}
OUT=${2:-/tmp}
for s in interior turntable mirror-box; do
  D="$OUT/bd-$s"
  mkdir -p "$D"
  [ -f "$D/cap/manifest.json" ] ||
    "$B"/calf-capture --scene "$s" --face-size 128 --threads 2 --quiet --out "$D/cap"
  [ -f "$D/gt/eye_path.json" ] ||
    "$B"/calf-capture --scene "$s" --ground-truth --gt-size 128x128 --threads 2 --quiet --out "$D/gt"
  [ -f "$D/lf.calf" ] || "$B"/calf-encode "$D/cap" -o "$D/lf.calf" --threads 2 --quiet
  [ -f "$D/ll.calf" ] ||
    "$B"/calf-encode "$D/cap" -o "$D/ll.calf" --color-format rgba16f --threads 2 --quiet
  echo "== $s"
  "$B"/calf-play "$D/lf.calf" --headless --compare "$D/gt" --breakdown "$D/cap" \
    --breakdown-lossless "$D/ll.calf" --out "$D/out" | grep -E "^(error|mean|noise)"
done
