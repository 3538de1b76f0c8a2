#!/usr/bin/env bash
# The Blender add-on (blender/calf_capture) end to end, headless:
#   blender_capture.sh playback BIN_DIR SRC_DIR WORK_DIR MIN_DB
#     builds the test scene (tests/blender/make_scene.py: checker-textured floor and wall, a moving
#     cube, a glossy sphere; 3 viewpoints from a collection, view volume from a box object, 3
#     frames), renders its capture set (faces of 32, 16 samples) and ground truth along the
#     camera's animation (64 x 48, noise floor at seed + 1), encodes it with calf-encode, verifies
#     the clip with calf-verify and plays it with calf-play --compare: the mean PSNR must reach
#     MIN_DB.
#   blender_capture.sh room BIN_DIR SRC_DIR WORK_DIR BOX_ROOM_CHECK
#     renders a box room with a block in it (tests/blender/box_room.py) from two viewpoints, with
#     coverage, and checks every texel's radial depth against the distance along calf's
#     direction_from_texel and its coverage against the cells' distances
#     (tests/capture/box_room_check.cc): fails on a wrong face order, orientation, depth or cell
#     order.
#   blender_capture.sh gltf BIN_DIR SRC_DIR WORK_DIR MIN_DB
#     exports the test scene as glTF with Blender's exporter (tests/blender/export_gltf.py:
#     procedural textures baked to images, the animation retimed to calf-capture's 30 fps, the
#     camera's animation written as an eye path), captures the file with calf-capture from the
#     same three viewpoints (faces of 32) and its ground truth along the same eye path (64 x 48),
#     encodes, verifies and plays it with calf-play --compare: the mean PSNR against calf's own
#     ground truth must reach MIN_DB.
#   blender_capture.sh errors BIN_DIR SRC_DIR WORK_DIR
#     each refusal is one line with its id and exit status, and leaves no manifest.
# Without Blender it is skipped (exit 77, one line), except with CI=true, where it fails.
set -euo pipefail
mode=$1 bin=$2 src=$3 work=$4
. "$src/tests/cli/require_tools.sh"
require_tools blender_capture "" blender
rm -rf "$work"
mkdir -p "$work"
cd "$work"
cli="$src/blender/calf_capture/cli.py"
blend() {  # scene script, then the add-on's arguments; prints the add-on's lines
  local scene=$1 rc
  shift
  set +e
  blender -b --factory-startup -noaudio -P "$src/tests/blender/$scene" -P "$cli" -- --threads 2 \
    "$@" 2>&1 | grep '^calf-blender'
  rc=${PIPESTATUS[0]}
  set -e
  return "$rc"
}
play_above() {  # plays clip.calf against gt/ and fails below MIN_DB
  local out psnr
  "$bin/calf-encode" cap -o clip.calf --quiet
  "$bin/calf-verify" clip.calf
  out=$("$bin/calf-play" clip.calf --headless --renderer cpu --compare gt)
  echo "$out" | grep -E '^(mean PSNR|noise floor)'
  psnr=$(echo "$out" | sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p')
  if awk -v a="$psnr" -v b="$1" 'BEGIN { exit !(a >= b) }'; then
    echo "blender_capture: $mode: mean PSNR $psnr dB >= $1 dB"
  else
    echo "blender_capture: FAIL $mode: mean PSNR $psnr dB below $1 dB"
    exit 1
  fi
}
case $mode in
  playback)
    min_db=$5
    blend make_scene.py --out cap --collection calf_viewpoints --volume-object calf_volume \
      --face-size 32 --samples 16 | tail -n 2
    blend make_scene.py --out gt --ground-truth --camera Eye --gt-size 64x48 --samples 16 | tail -n 1
    play_above "$min_db"
    ;;
  gltf)
    min_db=$5
    blender -b --factory-startup -noaudio --python-exit-code 1 \
      -P "$src/tests/blender/make_scene.py" -P "$src/tests/blender/export_gltf.py" -- \
      "$work/scene.gltf" --camera Eye --eye-path eye.json --size 64x48 --bake-size 256 2>&1 |
      grep '^export_gltf'
    # The file holds what the comparison needs: both checker textures baked into images, and the
    # cube's animation at 0, 1/30 and 2/30 s (capture frames 0-2 of calf-capture).
    python3 - <<'PY'
import json
g = json.load(open("scene.gltf"))
textured = sum("baseColorTexture" in m.get("pbrMetallicRoughness", {}) for m in g["materials"])
times = [(g["accessors"][s["input"]]["min"][0], g["accessors"][s["input"]]["max"][0])
         for a in g.get("animations", []) for s in a["samplers"]]
ok = textured == 2 and times and all(lo == 0 and abs(hi - 2 / 30) < 1e-6 for lo, hi in times)
print("blender_capture: glTF with %d textured materials, animation times %s%s"
      % (textured, times[:1], "" if ok else " FAIL: want 2, [(0, 2/30)]"))
raise SystemExit(0 if ok else 1)
PY
    # The collection's empties a, b, c in calf's frame, calf (x, y, z) = Blender (x, z, -y); their
    # box is the add-on's view volume (the box object calf_volume) too.
    "$bin/calf-capture" --scene scene.gltf --rig "list:-0.3,1,0.2/0.3,1.2,0.2/0,1.1,-0.3" \
      --frames 3 --face-size 32 --threads 2 --quiet --out cap
    "$bin/calf-capture" --scene scene.gltf --eye-path eye.json --threads 2 --quiet --out gt
    play_above "$min_db"
    ;;
  room)
    blend box_room.py --out room --rig "list:0,0,0/0.4,0.3,-0.2" --face-size 16 --samples 1 \
      --coverage | tail -n 1
    "$5" room -1.5,-0.8,-1.3,2.1,1.7,1.9 0.6,-0.5,0.5,1.2,0.2,1.1 1e-4
    ;;
  errors)
    # The refusals in one Blender process (tests/blender/error_cases.py), then one of them through
    # the command itself: one line on stderr, exit status 2, no manifest.
    blender -b --factory-startup -noaudio -P "$src/tests/blender/error_cases.py" -- "$work" \
      2>&1 | grep '^error_cases'
    set +e
    blender -b --factory-startup -noaudio -P "$cli" -- --out "$work/big" --rig list:0,1,0 \
      --face-size 16385 >/dev/null 2>stderr.txt
    rc=$?
    set -e
    line=$(cat stderr.txt)
    if [ "$rc" = 2 ] && [ "$(echo "$line" | wc -l)" = 1 ] &&
       echo "$line" | grep -qE '^calf-blender: CALF-E006 face size 16385 ' && ! [ -e big/manifest.json ]; then
      echo "blender_capture: the command: exit $rc, $line"
    else
      echo "blender_capture: FAIL the command: exit $rc (want 2), stderr: $line"
      exit 1
    fi
    ;;
  *)
    echo "blender_capture: unknown mode $mode"
    exit 2
    ;;
esac
