#!/usr/bin/env bash
# Reproduces docs/SURFELS.md "Measured on the factory" (the playback acceptance): export the
# factory, ray-cast its surfel candidates, build the surfel clip and the full-mesh clip, write a
# walk at ground level, then
#   1. play the surfels against the full mesh along the walk at each point size of SIZES
#      (calf-play --headless --compare-clip): SSIM / PSNR / epsilon and both render times;
#   2. run the frame-time controller over a longer walk at TARGET_MS (RUNS times on the wall
#      clock, once on the process CPU clock at CPU_TARGET_MS) and count the poses whose time lies
#      within +-10 % of the target (the first WARMUP poses, while the model learns, are left out).
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
#   TARGET_MS  controller target (default 100; reachable: at its finest detail the factory takes
#              ~135 ms a frame on an idle machine); POSES of the controller walk (default 24);
#   RUNS       controller runs on the wall clock (default 2: the machine's noise shows between
#              them); CPU_TARGET_MS a further run on the process CPU clock ("" skips; default
#              120); WARMUP controller poses left out (default 4);
#   GT_SIZE    pose image size (default 320x240); SKIP_COMPARE=1 skips step 1 (the full mesh's
#              minutes) and BUILD=0 reuses WORK_DIR's clips.
set -euo pipefail

B=${1:-build/rel}
W=${2:-/tmp/calf-surfel-eval}
SCENE=${SCENE:-factory}
RES=${RES:-256}
SURFELS=${SURFELS:-32768}
SIZES=${SIZES:-"2 1.5"}
FOVEATION=${FOVEATION-0.35,0.75,2}
TARGET_MS=${TARGET_MS:-100}
POSES=${POSES:-24}
WARMUP=${WARMUP:-4}
RUNS=${RUNS:-2}
CPU_TARGET_MS=${CPU_TARGET_MS-120}
SKIP_COMPARE=${SKIP_COMPARE:-0}
BUILD=${BUILD:-1}
GT_SIZE=${GT_SIZE:-320x240}
mkdir -p "$W"

if [[ $BUILD != 0 ]]; then
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
fi

runs=()
for size in $SIZES; do runs+=("$size:"); done
[[ -n $FOVEATION ]] && runs+=("2:$FOVEATION")
summary=()
[[ $SKIP_COMPARE != 0 ]] && runs=()
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

# One controller run: clock, target, log. Prints "K of N poses within +-10 % ..." and appends the
# per-pose figures (pose, time the controller follows, target, point size, near triangles) to
# $W/controller.dat as one gnuplot data block.
controller_run() {
  local clock=$1 target=$2 log=$3
  "$B/calf-play" "$W/s.calf" --headless --eye-path "$W/walk$POSES/eye_path.json" \
    --surfel-target-ms "$target" --surfel-clock "$clock" >"$log"
  printf '# %s clock, target %s ms (%s)\n' "$clock" "$target" "$(basename "$log")" >>"$W/controller.dat"
  grep -E '^pose [0-9]+ frame' "$log" | awk -v t="$target" -v w="$WARMUP" -v clock="$clock" \
    -v dat="$W/controller.dat" '{
    pose = $2 + 0; tri = $5 + 0
    match($0, /render [0-9.]+ ms/); wall = substr($0, RSTART + 7, RLENGTH - 10) + 0
    match($0, /at [0-9.]+ px/); px = substr($0, RSTART + 3, RLENGTH - 6) + 0
    match($0, /of [0-9.]+ ms\)/); cpu = substr($0, RSTART + 3, RLENGTH - 7) + 0
    ms = clock == "cpu" ? cpu : wall
    if (pose == 0) next                       # shader compilation, never reported
    printf "%d %.1f %s %.3f %d %.1f %.1f\n", pose, ms, t, px, tri, wall, cpu >> dat
    if (pose <= w) { warm = warm sprintf(" %.0f", ms); next }
    total++; if (ms >= 0.9 * t && ms <= 1.1 * t) ok++
    list = list sprintf(" %.0f", ms)
  } END {
    printf "%d of %d poses within +-10 %% of %d ms (%s clock; poses %d-: %s; warm-up:%s)", ok, total,
      t, clock, w + 1, list, warm
  }'
  printf '\n\n' >>"$W/controller.dat"
}

: >"$W/controller.dat"
echo "# pose, controlled ms, target ms, point size px, mesh triangles, wall ms, CPU ms" >>"$W/controller.dat"
controller=()
for k in $(seq 1 "$RUNS"); do
  echo "== controller run $k: target $TARGET_MS ms (wall clock) over $POSES poses"
  controller+=("$(controller_run wall "$TARGET_MS" "$W/controller-wall-$k.log")")
  echo "${controller[-1]}"
done
if [[ -n $CPU_TARGET_MS ]]; then
  echo "== controller: target $CPU_TARGET_MS ms of process CPU time over $POSES poses"
  controller+=("$(controller_run cpu "$CPU_TARGET_MS" "$W/controller-cpu.log")")
  echo "${controller[-1]}"
fi

echo
echo "== summary ($SCENE; $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg))"
for line in "${summary[@]}"; do echo "$line"; done
for line in "${controller[@]}"; do echo "controller: $line"; done
echo "per-pose figures: $W/controller.dat (docs/bench/surfel_controller.gp plots them)"
