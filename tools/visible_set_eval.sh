#!/usr/bin/env bash
# Reproduces docs/VISIBILITY.md "Measured" (the acceptance on real runs): for each scene,
# export it as a scene file, encode the full scene and its visible set (calf-encode --mode mesh
# [--visible-set]), write a walk trace inside the view region (the scene's validation eye path,
# see below), play the visible set against the full scene along it (calf-play --headless
# --compare-clip) with the GL rasteriser (llvmpipe through OSMesa) and the CPU reference, and
# print one summary row per scene. Then the from-segment / from-point comparison of
# bench-visible_set_bench. Not run by CI: it takes minutes (hours at face 800 on 2 cores).
#
#   tools/visible_set_eval.sh [BUILD_DIR [WORK_DIR]]
#
# BUILD_DIR (default build/rel) must hold calf-capture, calf-encode, calf-play, calf-info and
# tests/bench-visible_set_bench (cmake --build BUILD_DIR --target calf-capture calf-encode
# calf-play calf-info bench-visible_set_bench). Environment:
#   SCENES   "name:frames:face ..." (default "spheres:24:800 city:12:800 blades:12:800 MODEL:0:800"):
#            a built-in scene or a model file, the frames exported and walked (0: the scene's
#            own, walked with 12 poses) and the cube face size of the builder (paper 004: 800);
#   MODEL    the model file from outside the project (default: assimp-testmodels' 2CylinderEngine
#            glTF, apt-get install assimp-testmodels);
#   RIG      a calf-capture --rig for the view region and walk (default: each scene's own);
#   GT_SIZE  pose image size (default 320x240); THREADS (default 0: all cores);
#   BENCH    arguments of bench-visible_set_bench ("" skips it; default: the paper's face 800).
#
# The walk trace: calf-capture has no command that writes only an eye path, so the scene's
# validation path is written by --ground-truth with the cheapest settings (no AO rays, no
# bounces); its images are not used (the mesh comparison needs poses only).
set -euo pipefail

B=${1:-build/rel}
W=${2:-/tmp/calf-visible-set-eval}
MODEL=${MODEL:-/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb}
SCENES=${SCENES:-"spheres:24:800 city:12:800 blades:12:800 MODEL:0:800"}
GT_SIZE=${GT_SIZE:-320x240}
RIG=${RIG:-default}
THREADS=${THREADS:-0}
BENCH=${BENCH-"--face 800"}
mkdir -p "$W"

now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

summary=()
for spec in $SCENES; do
  IFS=: read -r scene frames face <<<"$spec"
  [[ $scene == MODEL ]] && scene=$MODEL
  name=$(basename "$scene")
  name=${name%.*}
  d=$W/$name
  rm -rf "$d"
  mkdir -p "$d"
  frame_args=()
  walk_args=(--frames 12) # a static model has 1 frame: still walk 12 poses
  ((frames > 0)) && frame_args=(--frames "$frames") && walk_args=(--frames "$frames")
  echo "== $name (frames ${frames/#0/scene\'s}, face $face)"
  "$B/calf-capture" --scene "$scene" --export-scene "$d/scene" "${frame_args[@]}" --rig "$RIG" \
    --quiet
  "$B/calf-encode" --mode mesh "$d/scene" -o "$d/full.calf" --threads "$THREADS" -q \
    2>"$d/full.log"
  t0=$(now)
  "$B/calf-encode" --mode mesh "$d/scene" -o "$d/visible.calf" --visible-set \
    --visibility-face-size "$face" --threads "$THREADS" 2>&1 | tee "$d/visible.log"
  t1=$(now)
  "$B/calf-capture" --scene "$scene" --out "$d/walk" --ground-truth --gt-size "$GT_SIZE" \
    --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor "${walk_args[@]}" --quiet
  for r in gl cpu; do
    "$B/calf-play" "$d/visible.calf" --headless --eye-path "$d/walk/eye_path.json" \
      --compare-clip "$d/full.calf" --renderer "$r" >"$d/play-$r.log" 2>&1
    tail -n 2 "$d/play-$r.log"
  done
  share=$(grep -o '[0-9]* of [0-9]* triangles ([0-9.]* %) in [0-9.]* s' \
    "$d/visible.log")
  eps=$(grep -o 'epsilon mean [0-9.]* % max [0-9.]* %' "$d/play-gl.log")
  psnr=$(grep -o 'PSNR mean [0-9.a-z]* dB min [0-9.a-z]* dB' "$d/play-gl.log")
  ssim=$(grep -o 'SSIM mean [0-9.]* min [0-9.]*' "$d/play-gl.log")
  gl=$(grep -o '[0-9.]* ms this clip, [0-9.]* ms full scene' "$d/play-gl.log")
  cpu=$(grep -o '[0-9.]* ms this clip, [0-9.]* ms full scene' "$d/play-cpu.log")
  summary+=("$name face $face: $share (encode wall $(secs "$t0" "$t1") s); GL $eps, $psnr, $ssim;
    frame GL $gl; CPU $cpu")
done

echo
echo "== summary (acceptance: epsilon mean <= 0.19 %, max <= 2.26 %; city set <= 10 %)"
for s in "${summary[@]}"; do echo "$s"; done

if [[ -n $BENCH ]]; then
  echo
  echo "== bench-visible_set_bench $BENCH (from-segment vs from-point; acceptance >= 1.2x)"
  # shellcheck disable=SC2086
  "$B/tests/bench-visible_set_bench" $BENCH
fi
