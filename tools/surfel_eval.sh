#!/usr/bin/env bash
# Reproduces docs/SURFELS.md "Measured on the factory" (issue 20's playback acceptance): export the
# factory, ray-cast its surfel candidates, build the surfel clip and the full-mesh clip, write a
# walk at ground level, then
#   1. play the surfels against the full mesh along the walk at each point size of SIZES
#      (calf-play --headless --compare-clip): SSIM / PSNR / epsilon and both render times;
#   2. run the frame-time controller over a longer walk at TARGET_MS and count the poses whose
#      render time lies within +-10 % of the target (the first WARMUP poses, while the point size
#      settles, are left out and printed apart).
# Not run by CI: it takes minutes (the full mesh is ~20 s a frame on llvmpipe). Run it on an idle
# machine: every render time it prints is wall time.
#
#   tools/surfel_eval.sh [BUILD_DIR [WORK_DIR]]
#
# BUILD_DIR (default build/rel) must hold calf-capture, calf-encode and calf-play. Environment:
#   SCENE      a built-in scene or model file (default factory);
#   RES        candidate G-buffer resolution (default 256); SURFELS per prototype (default 32768);
#   SIZES      point sizes of step 1 (default "2 1.5");
#   FOVEATION  INNER,OUTER,SCALE for an extra step-1 run with foveation ("" skips; default
#              0.35,0.75,2);
#   TARGET_MS  controller target (default 400); POSES of the controller walk (default 24);
#   WARMUP     controller poses left out (default 4); GT_SIZE pose image size (default 320x240).
set -euo pipefail

B=${1:-build/rel}
W=${2:-/tmp/calf-surfel-eval}
SCENE=${SCENE:-factory}
RES=${RES:-256}
SURFELS=${SURFELS:-32768}
SIZES=${SIZES:-"2 1.5"}
FOVEATION=${FOVEATION-0.35,0.75,2}
TARGET_MS=${TARGET_MS:-400}
POSES=${POSES:-24}
WARMUP=${WARMUP:-4}
GT_SIZE=${GT_SIZE:-320x240}
mkdir -p "$W"

echo "== build ($SCENE, candidates at $RES, at most $SURFELS surfels per prototype)"
"$B/calf-capture" --scene "$SCENE" --export-scene "$W/scene" --frames 4 --quiet
"$B/calf-capture" --scene "$W/scene" --surfel-candidates "$W/c.cand" --surfel-resolution "$RES"
"$B/calf-encode" --mode surfels "$W/scene" --surfel-candidates "$W/c.cand" -o "$W/s.calf" \
  --surfels "$SURFELS"
"$B/calf-encode" --mode mesh "$W/scene" -o "$W/full.calf" -q
# The walks: calf-capture writes the scene's validation path with its cheapest ground truth.
"$B/calf-capture" --scene "$SCENE" --out "$W/walk" --ground-truth --gt-size "$GT_SIZE" \
  --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor --frames 4 --quiet
"$B/calf-capture" --scene "$SCENE" --out "$W/walk$POSES" --ground-truth --gt-size "$GT_SIZE" \
  --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor --frames "$POSES" --quiet

runs=()
for size in $SIZES; do runs+=("$size:"); done
[[ -n $FOVEATION ]] && runs+=("2:$FOVEATION")
summary=()
for run in "${runs[@]}"; do
  IFS=: read -r size fov <<<"$run"
  args=(--surfel-point-size "$size")
  label="point size $size"
  [[ -n $fov ]] && args+=(--surfel-foveation "$fov") && label+=", foveation $fov"
  echo "== against the full mesh: $label"
  log=$W/compare-$size${fov:+-fov}.log
  "$B/calf-play" "$W/s.calf" --headless --eye-path "$W/walk/eye_path.json" \
    --compare-clip "$W/full.calf" "${args[@]}" | tee "$log"
  summary+=("$label: $(grep -E '^against the full scene' "$log" | head -1)")
done

echo "== controller: target $TARGET_MS ms over $POSES poses"
log=$W/controller.log
"$B/calf-play" "$W/s.calf" --headless --eye-path "$W/walk$POSES/eye_path.json" \
  --surfel-target-ms "$TARGET_MS" | tee "$log"
controller=$(grep -oE 'pose [0-9]+ frame [0-9]+: .*render [0-9.]+ ms' "$log" |
  awk -v t="$TARGET_MS" -v w="$WARMUP" '{
    n = split($0, f, " "); ms = f[n - 1]; pose = f[2] + 0
    if (pose == 0) next                       # shader compilation, never reported
    if (pose <= w) { warm = warm sprintf(" %.0f", ms); next }
    total++; if (ms >= 0.9 * t && ms <= 1.1 * t) ok++
  } END { printf "%d of %d poses within +-10 %% of %d ms (warm-up poses:%s)", ok, total, t, warm }')

echo
echo "== summary ($SCENE; $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg))"
for line in "${summary[@]}"; do echo "$line"; done
echo "controller: $controller"
