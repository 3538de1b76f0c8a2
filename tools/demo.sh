#!/usr/bin/env bash
# The README's demo command: installs what is missing, builds in Release and runs the end-to-end
# pipeline on a built-in sample: ray-trace a capture set of the animated `interior` scene, encode
# it into a .calf clip, summarise and fully verify the clip, render ground truth along the scene's
# eye path and play the clip headless along it (GL through OSMesa), comparing every frame with the
# ground truth. Ends with a one-screen report and a contact sheet PNG (ground truth | calf | error
# heat map). Then the visible-set mesh mode (paper 004, docs/VISIBILITY.md) on the built-in
# `city` (1.4 M triangles): export the scene file, encode the full scene and the triangles visible
# from the view region's perimeter as mesh clips, and play the visible set against the full scene
# along a walk inside the region (epsilon = share of pixels where a triangle is missing, PSNR,
# SSIM, frame times). Then the surfel mode (paper 001, docs/SURFELS.md) on the built-in
# `factory` (28 M triangles counting instances): export the scene file, ray-cast surfel
# candidates at a small G-buffer size, build the surfel clip and the full mesh clip, and play the
# surfels against the full mesh along the factory's ground-level walk (bytes, build s, render ms,
# PSNR / SSIM). Then the tiles mode (paper 000, docs/TILES.md): layered quad tiles with an RGBA
# atlas built from frame 0 of the same capture set, played along the ground-truth path with the
# scene held at frame 0, beside the light field on the same poses (bytes, build s, render ms,
# PSNR / SSIM). Every step's full output is kept in build/demo/logs/. A second run skips
# installed packages and rebuilds incrementally.
#
# Environment: CALF_DEMO_SCENE (default interior; see calf-capture --list-scenes),
# CALF_DEMO_FACE (capture face size, default 64), CALF_DEMO_FRAMES (default 8),
# CALF_DEMO_GT (ground-truth size WxH, default 128x128); visible-set part: CALF_DEMO_VS_SCENE
# (default city; empty skips the part), CALF_DEMO_VS_FACE (the builder's cube face, default 200;
# the paper's 800 takes minutes), CALF_DEMO_VS_FRAMES (frames solved and walk poses, default 6);
# surfel part: CALF_DEMO_SURFEL_SCENE (default factory; empty skips the part),
# CALF_DEMO_SURFEL_RES (candidate G-buffer size, default 128; docs/SURFELS.md measures 256),
# CALF_DEMO_SURFEL_COUNT (most surfels per prototype, default 8192), CALF_DEMO_SURFEL_POSES
# (walk poses, default 2: the full mesh takes tens of seconds a pose on llvmpipe);
# tiles part: CALF_DEMO_TILES (default 1; empty skips the part), CALF_DEMO_TILES_TRIANGLES
# (the triangle budget, default 72000);
# Blender part (off by default): CALF_DEMO_BLENDER=1 renders a small animated scene built by
# script (tests/blender/make_scene.py) with the Blender add-on (blender/calf_capture, Cycles):
# capture set and ground truth, then encodes and plays it against Blender's own images.
# CALF_DEMO_BUILD (build directory, default build/release).
set -euo pipefail
cd "$(dirname "$0")/.."
DEMO_T0=$(date +%s.%N)
./tools/setup.sh
BUILD=${CALF_DEMO_BUILD:-build/release}
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" --target calf-capture calf-encode calf-info calf-verify calf-play

SCENE=${CALF_DEMO_SCENE:-interior}
FACE=${CALF_DEMO_FACE:-64}
FRAMES=${CALF_DEMO_FRAMES:-8}
GT=${CALF_DEMO_GT:-128x128}
VS_SCENE=${CALF_DEMO_VS_SCENE-city}
VS_FACE=${CALF_DEMO_VS_FACE:-200}
VS_FRAMES=${CALF_DEMO_VS_FRAMES:-6}
OUT=build/demo
LOGS=$OUT/logs
CLIP=$OUT/$SCENE.calf
SHEET=$OUT/contact_sheet.png
VS=$OUT/visible-set
# --- surfel mode settings (paper 001)
SF_SCENE=${CALF_DEMO_SURFEL_SCENE-factory}
SF_RES=${CALF_DEMO_SURFEL_RES:-128}
SF_COUNT=${CALF_DEMO_SURFEL_COUNT:-8192}
SF_POSES=${CALF_DEMO_SURFEL_POSES:-2}
SF=$OUT/surfels
# --- tiles mode settings (paper 000)
TL_ON=${CALF_DEMO_TILES-1}
TL_TRIANGLES=${CALF_DEMO_TILES_TRIANGLES:-72000}
TL=$OUT/tiles
# --- Blender part (docs/BLENDER.md)
BL_ON=${CALF_DEMO_BLENDER-}
BL=$OUT/blender
rm -rf "$OUT"
mkdir -p "$LOGS"

now() { date +%s.%N; }
seconds_since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
# run NAME COMMAND...: runs a step with its output in $LOGS/NAME.log; on failure shows the log's
# end and stops the demo with the step's exit status.
run() {
  local name=$1 t0 status=0
  shift
  t0=$(now)
  printf '%-34s' "== $name"
  "$@" >"$LOGS/$name.log" 2>&1 || status=$?
  if [ "$status" -ne 0 ]; then
    echo "FAILED (exit $status)"
    tail -n 20 "$LOGS/$name.log" >&2
    echo "demo: $name failed; full output in $LOGS/$name.log" >&2
    exit "$status"
  fi
  LAST_SECONDS=$(seconds_since "$t0")
  echo "done in $LAST_SECONDS s"
}
# line_of FILE REGEX: the first line of FILE matching REGEX, or "n/a".
line_of() { grep -m1 -E "$2" "$1" || echo "n/a"; }

echo "calf demo: scene $SCENE, ${FACE}² cube faces, $FRAMES frames, ground truth $GT"
run calf-capture "$BUILD"/calf-capture --scene "$SCENE" --out "$OUT/capture" --face-size "$FACE" \
  --frames "$FRAMES"
CAPTURE_S=$LAST_SECONDS
run calf-encode "$BUILD"/calf-encode "$OUT/capture/manifest.json" -o "$CLIP"
ENCODE_S=$LAST_SECONDS
run calf-info "$BUILD"/calf-info "$CLIP"
run calf-verify "$BUILD"/calf-verify "$CLIP"
run ground-truth "$BUILD"/calf-capture --scene "$SCENE" --ground-truth --out "$OUT/ground-truth" \
  --frames "$FRAMES" --gt-size "$GT"
run calf-play "$BUILD"/calf-play "$CLIP" --headless --compare "$OUT/ground-truth" \
  --out "$OUT/play" --contact-sheet "$SHEET"

# --- tiles mode (paper 000): a self-contained block; its report lines are printed below.
if [ -n "$TL_ON" ]; then
  echo "calf demo: tiles mode from frame 0 of the same capture, at most $TL_TRIANGLES triangles"
  mkdir -p "$TL"
  run tl-encode "$BUILD"/calf-encode --mode tiles "$OUT/capture/manifest.json" -o "$TL/tiles.calf" \
    --tiles-triangles "$TL_TRIANGLES" --quiet
  TL_BUILD_S=$LAST_SECONDS
  # Tiles hold one frame (a static view region): the ground truth's poses with the scene held at
  # frame 0 (every pose's time set to 0), and the light field played on the same poses beside them.
  sed -E 's/"time": *[-+0-9.eE]+/"time": 0/' "$OUT/ground-truth/eye_path.json" >"$TL/frame0_path.json"
  run tl-ground-truth "$BUILD"/calf-capture --scene "$SCENE" --ground-truth --eye-path \
    "$TL/frame0_path.json" --out "$TL/ground-truth" --quiet
  run tl-play "$BUILD"/calf-play "$TL/tiles.calf" --headless --compare "$TL/ground-truth" \
    --out "$TL/play"
  run tl-play-lightfield "$BUILD"/calf-play "$CLIP" --headless --compare "$TL/ground-truth" \
    --out "$TL/play-lightfield"
fi
# --- end of the tiles mode

if [ -n "$VS_SCENE" ]; then
  echo "calf demo: visible-set mesh mode on $VS_SCENE, face $VS_FACE, $VS_FRAMES frames"
  run vs-export-scene "$BUILD"/calf-capture --scene "$VS_SCENE" --export-scene "$VS/scene" \
    --frames "$VS_FRAMES" --quiet
  run vs-encode-full "$BUILD"/calf-encode --mode mesh "$VS/scene" -o "$VS/full.calf"
  run vs-encode-visible "$BUILD"/calf-encode --mode mesh "$VS/scene" -o "$VS/visible.calf" \
    --visible-set --visibility-face-size "$VS_FACE"
  VS_BUILD_S=$LAST_SECONDS
  # The walk: the scene's validation eye path inside the region. calf-capture writes it with
  # --ground-truth; the mesh comparison uses its poses only, so the images are the cheapest kind.
  run vs-walk "$BUILD"/calf-capture --scene "$VS_SCENE" --out "$VS/walk" --ground-truth \
    --gt-size 320x240 --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor --frames "$VS_FRAMES" --quiet
  run vs-play "$BUILD"/calf-play "$VS/visible.calf" --headless --eye-path "$VS/walk/eye_path.json" \
    --compare-clip "$VS/full.calf"
fi

# --- surfel mode (paper 001): a self-contained block; its report lines are printed below.
if [ -n "$SF_SCENE" ]; then
  echo "calf demo: surfel mode on $SF_SCENE, candidates at ${SF_RES}², at most $SF_COUNT surfels" \
    "per prototype, $SF_POSES poses"
  run sf-export-scene "$BUILD"/calf-capture --scene "$SF_SCENE" --export-scene "$SF/scene" \
    --frames "$SF_POSES" --quiet
  run sf-candidates "$BUILD"/calf-capture --scene "$SF/scene" --surfel-candidates "$SF/c.cand" \
    --surfel-resolution "$SF_RES"
  SF_CAND_S=$LAST_SECONDS
  run sf-encode-surfels "$BUILD"/calf-encode --mode surfels "$SF/scene" \
    --surfel-candidates "$SF/c.cand" -o "$SF/surfels.calf" --surfels "$SF_COUNT"
  SF_BUILD_S=$LAST_SECONDS
  run sf-encode-full "$BUILD"/calf-encode --mode mesh "$SF/scene" -o "$SF/full.calf"
  # The walk: the scene's ground-level validation path (its poses only; the cheapest images).
  run sf-walk "$BUILD"/calf-capture --scene "$SF_SCENE" --out "$SF/walk" --ground-truth \
    --gt-size 320x240 --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor --frames "$SF_POSES" \
    --quiet
  run sf-play "$BUILD"/calf-play "$SF/surfels.calf" --headless \
    --eye-path "$SF/walk/eye_path.json" --compare-clip "$SF/full.calf"
fi
# --- end of the surfel mode

# --- Blender part: the add-on renders a scene built by script; calf plays it against Cycles.
if [ -n "$BL_ON" ] && ! command -v blender >/dev/null; then
  echo "calf demo: CALF_DEMO_BLENDER is set but blender is not installed (tools/setup.sh installs" \
    "it); skipping the Blender part"
  BL_ON=
fi
if [ -n "$BL_ON" ]; then
  echo "calf demo: Blender add-on on tests/blender/make_scene.py (3 viewpoints, 3 frames, faces" \
    "of 32, 16 samples)"
  BLENDER_RUN=(blender -b --factory-startup -noaudio -P tests/blender/make_scene.py
    -P blender/calf_capture/cli.py --)
  run bl-capture "${BLENDER_RUN[@]}" --out "$BL/capture" --collection calf_viewpoints \
    --volume-object calf_volume --face-size 32 --samples 16
  BL_CAPTURE_S=$LAST_SECONDS
  run bl-ground-truth "${BLENDER_RUN[@]}" --out "$BL/ground-truth" --ground-truth --camera Eye \
    --gt-size 64x48 --samples 16
  run bl-encode "$BUILD"/calf-encode "$BL/capture" -o "$BL/scene.calf" --quiet
  run bl-play "$BUILD"/calf-play "$BL/scene.calf" --headless --compare "$BL/ground-truth" \
    --out "$BL/play"
fi
# --- end of the Blender part

PLAY=$LOGS/calf-play.log
ENC=$LOGS/calf-encode.log
CAPTURE_BYTES=$(du -sb "$OUT/capture" | cut -f1)
CLIP_BYTES=$(stat -c %s "$CLIP")
VIEWS=$(grep -c '"name"' "$OUT/capture/manifest.json" || true)
echo
echo "================================ calf demo report ================================"
printf 'scene     %s: %s viewpoints x 6 faces of %s², %s frames (calf-capture %s s)\n' \
  "$SCENE" "$VIEWS" "$FACE" "$FRAMES" "$CAPTURE_S"
awk -v c="$CAPTURE_BYTES" -v k="$CLIP_BYTES" -v clip="$CLIP" 'BEGIN {
  printf "clip      %s: %.2f MB, %.1fx smaller than the capture set'"'"'s %.1f MB of EXR\n",
         clip, k / 1e6, c / k, c / 1e6 }'
echo "          per stream: raw -> temporal -> spatial (BCn, log-16) -> zstd bytes, ratio to raw"
grep -E '^  (colour|depth|material) +raw' "$ENC" | sed 's/^  /            /' || true
echo "encode    $ENCODE_S s wall: $(line_of "$ENC" 'wrote .* in' | sed -E 's/.* in ([0-9.]+ s.*)/\1/'),"\
  "$(line_of "$ENC" 'peak RSS' | sed 's/^calf-encode: //')"
SUMMARY=$(line_of "$PLAY" '^[0-9]+ poses: ')
echo "playback  ${SUMMARY}"
echo "          (GL 4.5 through OSMesa / llvmpipe on the CPU; the first render compiles shaders)"
echo "quality   $(line_of "$PLAY" '^mean PSNR') against ground truth at $GT"
echo "          $(line_of "$PLAY" '^worst pose')"
echo "sheet     $SHEET (rows: poses along the path; ground truth | calf | error heat map)"
if [ -n "$VS_SCENE" ]; then
  VSLOG=$LOGS/vs-encode-visible.log
  VSPLAY=$LOGS/vs-play.log
  echo "visible   $VS_SCENE (paper 004): $(line_of "$VSLOG" 'visible set:' |
    grep -oE '[0-9]+ of [0-9]+ triangles \([0-9.]+ %\)') kept, from"\
    "$(line_of "$VSLOG" 'visible set:' | grep -oE '[0-9]+ segments')" \
    "at face $VS_FACE, $VS_FRAMES frames; build $VS_BUILD_S s wall"
  awk -v v="$(stat -c %s "$VS/visible.calf")" -v f="$(stat -c %s "$VS/full.calf")" 'BEGIN {
    printf "          mesh clip %.1f KB (the full scene: %.1f KB)\n", v / 1e3, f / 1e3 }'
  echo "          render $(line_of "$VSPLAY" '^frame time' | sed 's/^frame time ([^)]*): //')"\
    "(GL on llvmpipe, median after the first pose)"
  echo "          $(line_of "$VSPLAY" '^against the full scene' | sed -E 's/ \(an identical[^)]*\)//')"
  echo "          (epsilon: share of pixels where a triangle is missing; paper 004: <= 0.19 % mean)"
fi
# --- tiles mode report
if [ -n "$TL_ON" ]; then
  TLENC=$LOGS/tl-encode.log
  TLPLAY=$LOGS/tl-play.log
  echo "tiles     frame 0 of $SCENE (paper 000): $(line_of "$TLENC" 'wrote' |
    grep -oE '[0-9]+ tiles, [0-9]+ triangles, atlas [0-9]+ x [0-9]+')" \
    "(budget $TL_TRIANGLES); build $TL_BUILD_S s wall"
  awk -v t="$(stat -c %s "$TL/tiles.calf")" 'BEGIN { printf "          clip %.1f KB\n", t / 1e3 }'
  echo "          $(line_of "$TLENC" 'overdraw' | sed -E 's/^ +//')"
  echo "          render $(line_of "$TLPLAY" '^[0-9]+ poses: ' | sed -E 's/^[0-9]+ poses: //')"
  echo "          tiles:       $(line_of "$TLPLAY" '^mean PSNR')"
  echo "          light field: $(line_of "$LOGS/tl-play-lightfield.log" '^mean PSNR')"
  echo "          (the same poses, the scene held at frame 0; ground truth at $GT)"
fi
# --- surfel mode report
if [ -n "$SF_SCENE" ]; then
  SFENC=$LOGS/sf-encode-surfels.log
  SFPLAY=$LOGS/sf-play.log
  echo "surfels   $SF_SCENE (paper 001): $(line_of "$SFENC" 'wrote' |
    grep -oE '[0-9]+ surfels of [0-9]+ candidates')," \
    "$(line_of "$SFENC" 'wrote' | grep -oE '[0-9.]+ bytes per surfel')"
  awk -v s="$(stat -c %s "$SF/surfels.calf")" -v f="$(stat -c %s "$SF/full.calf")" \
    -v c="$SF_CAND_S" -v b="$SF_BUILD_S" 'BEGIN {
    printf "          clip %.2f MB (mesh + surfels; the full mesh alone %.2f MB); build %.1f s" \
           " (candidates %.1f s + surfels %.1f s)\n", s / 1e6, f / 1e6, c + b, c, b }'
  line_of "$SFPLAY" '^frame time' | awk '{
    match($0, /: [0-9.]+ ms this/); a = substr($0, RSTART + 2, RLENGTH - 12) + 0
    match($0, /, [0-9.]+ ms full/); b = substr($0, RSTART + 2, RLENGTH - 10) + 0
    if (a > 0) printf "          render %.0f ms a pose (the full mesh %.0f ms: %.0fx the frame rate;" \
      " GL on llvmpipe, 320x240)\n", a, b, b / a
    else print "          render n/a" }'
  echo "          $(line_of "$SFPLAY" '^against the full scene' |
    sed -E 's/ \(an identical[^)]*\)//; s/epsilon[^;]*; //')"
fi
# --- Blender part report
if [ -n "$BL_ON" ]; then
  echo "blender   the add-on's capture of make_scene.py: 3 viewpoints x 3 frames, faces of 32" \
    "(Blender + Cycles $BL_CAPTURE_S s)"
  echo "          $(line_of "$LOGS/bl-play.log" '^mean PSNR') against Cycles' ground truth at 64x48"
  echo "          $(line_of "$LOGS/bl-play.log" '^noise floor')"
fi
echo "total     $(seconds_since "$DEMO_T0") s wall, the whole demo (setup and build included)"
echo "files     capture set $OUT/capture, frames and heat maps $OUT/play, logs $LOGS"
echo "=================================================================================="
