#!/usr/bin/env bash
# Tiles mode (paper 000, docs/TILES.md) against the light field on the same capture, as Seurat's
# Table 1 measures it and at novel views:
#   1. calf-capture: one frame of SCENE (a built-in or a model file) at FACE² faces (converged
#      defaults unless CAPTURE_OPTS says otherwise);
#   2. calf-encode: the light-field clip and the tiles clip (TILES_OPTS, e.g. --tiles-triangles);
#   3. ground truth at the capture viewpoints (Seurat's protocol, Sec. 6: re-render each capture
#      viewpoint and compare with the captured samples: here its 6 cube faces at 90° x 90° and the
#      capture's own FACE² resolution, so every pixel is a capture texel, rendered again by
#      calf-capture with the capture's sampling; the noise floor says how far two renders of the
#      same samples differ) and along the scene's eye path at GT_SIZE with the scene held at
#      frame 0 (novel views inside the view region);
#   4. calf-play --headless --compare of both clips against both: PSNR / SSIM with the noise floor.
# Usage: tools/tiles_eval.sh BUILD_DIR OUT_DIR [SCENE] [FACE] [GT_SIZE]
# Environment: CAPTURE_OPTS (extra calf-capture options, e.g. "--rig box:..."), TILES_OPTS (extra
# calf-encode --mode tiles options), POSES (eye-path poses, default 8), NOVEL (path: the scene's
# own eye path, the default; rig: novel poses between the capture viewpoints, at 1/4, 1/2 and 3/4
# of the way from each to the next, looking at the world origin: for a rig placed outside a model,
# whose own eye path does not stay inside the rig's view region).
set -euo pipefail
BUILD=${1:?usage: tools/tiles_eval.sh BUILD_DIR OUT_DIR [SCENE] [FACE] [GT_SIZE]}
OUT=${2:?usage: tools/tiles_eval.sh BUILD_DIR OUT_DIR [SCENE] [FACE] [GT_SIZE]}
SCENE=${3:-interior}
FACE=${4:-128}
GT=${5:-128x128}
POSES=${POSES:-8}
read -r -a capture_opts <<<"${CAPTURE_OPTS:-}"
read -r -a tiles_opts <<<"${TILES_OPTS:-}"
mkdir -p "$OUT"
step() { echo "tiles_eval: $*" >&2; }
timed() { local t0; t0=$(date +%s.%N); "$@"; awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }' >"$OUT/.t"; }

step "capture $SCENE, face $FACE, 1 frame"
timed "$BUILD"/calf-capture --scene "$SCENE" --face-size "$FACE" --frames 1 --out "$OUT/capture" \
  --quiet "${capture_opts[@]}"
step "capture took $(cat "$OUT/.t") s"
timed "$BUILD"/calf-encode "$OUT/capture" -o "$OUT/lightfield.calf" --quiet 2>"$OUT/lightfield.log"
LF_S=$(cat "$OUT/.t")
timed "$BUILD"/calf-encode --mode tiles "$OUT/capture" -o "$OUT/tiles.calf" --quiet \
  "${tiles_opts[@]}" 2>"$OUT/tiles.log"
TL_S=$(cat "$OUT/.t")

# The capture viewpoints' eye path: 6 axis-aligned 90° views of every viewpoint at FACE x FACE, so
# each pixel centre is a capture texel centre. Any up vector along a face axis would do (the image
# only turns); these are upright, +Y up except looking up or down.
awk -v w="$FACE" '
  /"position": \[/ { inpos = 1; n = 0; next }
  inpos && /\]/ { inpos = 0; views[++count] = p[1] " " p[2] " " p[3]; next }
  inpos { gsub(/[ ,]/, ""); p[++n] = $0 }
  END {
    printf "{\n  \"format\": \"calf-eye-path\",\n  \"version\": 1,\n  \"width\": %d,\n  \"height\": %d,\n  \"poses\": [\n", w, w
    split("1 0 0;0 1 0|-1 0 0;0 1 0|0 1 0;0 0 -1|0 -1 0;0 0 1|0 0 1;0 1 0|0 0 -1;0 1 0", dirs, "|")
    first = 1
    for (v = 1; v <= count; ++v) {
      split(views[v], q, " ")
      for (d = 1; d <= 6; ++d) {
        if (!first) printf ",\n"
        first = 0
        split(dirs[d], fu, ";")
        split(fu[1], f, " ")
        split(fu[2], u, " ")
        printf "    {\"time\": 0, \"position\": [%s, %s, %s], \"forward\": [%s, %s, %s], \"up\": [%s, %s, %s], \"fov_y_degrees\": 90}", q[1], q[2], q[3], f[1], f[2], f[3], u[1], u[2], u[3]
      }
    }
    printf "\n  ]\n}\n"
  }' "$OUT/capture/manifest.json" >"$OUT/capture_views_path.json"

step "ground truth at the capture viewpoints"
"$BUILD"/calf-capture --scene "$SCENE" --ground-truth --eye-path "$OUT/capture_views_path.json" \
  --out "$OUT/gt-capture-views" --quiet "${capture_opts[@]}"
if [ "${NOVEL:-path}" = rig ]; then
  step "ground truth at novel poses between the capture viewpoints"
  awk -v w="${GT%x*}" -v h="${GT#*x}" '
    /"position": \[/ { inpos = 1; n = 0; next }
    inpos && /\]/ { inpos = 0; ++count; x[count] = p[1]; y[count] = p[2]; z[count] = p[3]; next }
    inpos { gsub(/[ ,]/, ""); p[++n] = $0 }
    END {
      printf "{\n  \"format\": \"calf-eye-path\",\n  \"version\": 1,\n  \"width\": %d,\n  \"height\": %d,\n  \"poses\": [\n", w, h
      first = 1
      for (v = 1; v <= count; ++v) {
        u = v % count + 1
        for (k = 1; k <= 3; ++k) {
          t = k / 4
          px = x[v] + t * (x[u] - x[v]); py = y[v] + t * (y[u] - y[v]); pz = z[v] + t * (z[u] - z[v])
          if (!first) printf ",\n"
          first = 0
          printf "    {\"time\": 0, \"position\": [%.6f, %.6f, %.6f], \"forward\": [%.6f, %.6f, %.6f], \"up\": [0, 1, 0], \"fov_y_degrees\": 60}", px, py, pz, -px, -py, -pz
        }
      }
      printf "\n  ]\n}\n"
    }' "$OUT/capture/manifest.json" >"$OUT/frame0_path.json"
else
  step "ground truth along the eye path, the scene at frame 0"
  # (only its poses are used: the cheapest images)
  "$BUILD"/calf-capture --scene "$SCENE" --ground-truth --frames "$POSES" --gt-size "$GT" \
    --out "$OUT/gt-path-animated" --no-noise-floor --quiet --spp 1 --ao-samples 0
  sed -E 's/"time": *[-+0-9.eE]+/"time": 0/' "$OUT/gt-path-animated/eye_path.json" \
    >"$OUT/frame0_path.json"
fi
"$BUILD"/calf-capture --scene "$SCENE" --ground-truth --eye-path "$OUT/frame0_path.json" \
  --out "$OUT/gt-path" --quiet "${capture_opts[@]}"

for clip in lightfield tiles; do
  for gt in capture-views path; do
    "$BUILD"/calf-play "$OUT/$clip.calf" --headless --compare "$OUT/gt-$gt" \
      >"$OUT/play-$clip-$gt.log" 2>&1
  done
done

echo "scene $SCENE, face $FACE, ground truth $GT"
echo "tiles build: $(grep -m1 -oE '[0-9]+ tiles, [0-9]+ triangles, atlas [0-9]+ x [0-9]+' "$OUT/tiles.log"), $TL_S s; light-field encode $LF_S s"
grep -E "overdraw|seconds|stage" "$OUT/tiles.log" | sed 's/^/  /' || true
printf '%-11s %-15s %s\n' clip "ground truth" "quality"
for clip in lightfield tiles; do
  for gt in capture-views path; do
    printf '%-11s %-15s %s\n' "$clip" "$gt" \
      "$(grep -m1 '^mean PSNR' "$OUT/play-$clip-$gt.log" || echo n/a)"
  done
  printf '%-11s %-15s %s\n' "$clip" "bytes" "$(stat -c %s "$OUT/$clip.calf")"
done
