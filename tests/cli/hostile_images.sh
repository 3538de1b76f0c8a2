#!/bin/sh
# Hostile images given to the commands that decode images, one case per run, each under a
# memory and time bound:
#   hostile_images.sh CASE BIN_DIR GENERATOR WORK_DIR MAX_KB MAX_SECONDS
# GENERATOR (tests/capture/hostile_images.cc) writes the small files into WORK_DIR (emptied
# first); the case runs one command under /usr/bin/time with its stdout and stderr passed through
# and exits with that command's status, so calf_add_cli_test checks the one line and the status.
# The bound is over the command's own start-up, measured first in the same run (`COMMAND --help`:
# the shared libraries it maps, and under AddressSanitizer its shadow and allocator, about 170 MB
# and seconds on a loaded machine): a case whose peak resident set exceeds that start-up's by
# more than MAX_KB, or whose wall time exceeds it by more than MAX_SECONDS, prints a second stderr
# line and exits 99, which fails the test whatever it expected.
set -u
name=$1
bin=$2
generate=$3
work=$4
max_kb=$5
max_s=$6
rm -rf "$work"
mkdir -p "$work"
"$generate" "$work" || exit 98
broken() {
  echo "$name: post-condition broken: $*" >&2
  echo "(second line, so that the test fails)" >&2
  exit 99
}
# run COMMAND...: runs COMMAND --help (or $base --help where COMMAND only wraps the command, as
# `sh -c 'ulimit ...'` does), then COMMAND... under /usr/bin/time; the status in rc.
base=
run() {
  /usr/bin/time -f '%M %e' -o "$work/time-base" "${base:-$1}" --help >/dev/null 2>&1
  /usr/bin/time -f '%M %e' -o "$work/time" timeout 60 "$@"
  rc=$?
}
# capture MODEL [OPTION...]: calf-capture of WORK_DIR/MODEL at faces of 8, one frame, through run.
capture() {
  local model=$1
  shift
  run "$bin/calf-capture" --scene "$work/$model" "$@" --face-size 8 --frames 1 --out "$work/out"
}
# A textured triangle (OBJ + MTL) whose map_Kd is $1; an embedded one (glTF, data URI) of $1.
textured_obj() {
  printf 'newmtl m\nmap_Kd %s\n' "$1" >"$work/model.mtl"
}
embedded_gltf() {
  tri=AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/
  png=$(base64 -w0 "$work/$1")
  cat >"$work/model.gltf" <<EOF
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
 "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
 "textures": [{"source": 0}],
 "images": [{"uri": "data:image/png;base64,$png"}],
 "buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,$tri"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                 {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]},
               {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]}
EOF
}

case $name in
# calf-ingest: headers against the camera (E147), the budget (E012), face sizes (E012)
ingest-png-header) run "$bin/calf-ingest" seurat "$work/seurat_png.json" "$work/out" ;;
ingest-exr-header) run "$bin/calf-ingest" seurat "$work/seurat_exr.json" "$work/out" ;;
ingest-exr-channels) run "$bin/calf-ingest" seurat "$work/seurat_wide.json" "$work/out" ;;
ingest-png-truncated) run "$bin/calf-ingest" seurat "$work/seurat_cut.json" "$work/out" ;;
ingest-face-size) run "$bin/calf-ingest" seurat --face-size 16384 "$work/seurat_png.json" "$work/out" ;;
ingest-implied-face-size) run "$bin/calf-ingest" seurat "$work/seurat_focal.json" "$work/out" ;;
ingest-equirect-budget) run "$bin/calf-ingest" equirect "$work/equirect.json" "$work/out" ;;
ingest-exr-attribute) run "$bin/calf-ingest" seurat "$work/seurat_attribute.json" "$work/out" ;;
ingest-equirect-face-size) run "$bin/calf-ingest" equirect --face-size 16384 "$work/equirect.json" "$work/out" ;;
# the budget raised past what the machine gives (a 2 GB address space): CALF-E013, never an abort
ingest-out-of-memory)
  base=$bin/calf-ingest
  run sh -c 'ulimit -v 2097152 && exec "$@"' sh "$bin/calf-ingest" seurat --face-size 16384 \
    --max-image-pixels 4294967296 "$work/seurat_png.json" "$work/out" ;;
# calf-capture: model textures, external and embedded
capture-texture-budget)
  textured_obj big.png
  capture model.obj ;;
capture-texture-header)
  textured_obj big.png
  capture model.obj --max-image-pixels 268435456 ;;
capture-embedded-budget)
  embedded_gltf big.png
  capture model.gltf ;;
capture-embedded-header)
  embedded_gltf big.png
  capture model.gltf --max-image-pixels 268435456 ;;
capture-texture-exr)
  textured_obj attribute.exr
  capture model.obj ;;
capture-embedded-exr)
  embedded_gltf attribute.exr
  capture model.gltf ;;
capture-embedded-truncated)
  embedded_gltf cut.png
  capture model.gltf ;;
# calf-encode --mode mesh: a scene file's texture (the scene exported from a model with a valid
# texture, whose PNG is then replaced)
encode-scene-texture)
  textured_obj ok.png
  "$bin/calf-capture" --scene "$work/model.obj" --export-scene "$work/scene" --frames 1 \
    --quiet >/dev/null 2>&1 || broken "the scene could not be exported"
  for t in "$work"/scene/textures/*.png; do cp "$work/big.png" "$t"; done
  run "$bin/calf-encode" --mode mesh "$work/scene" -o "$work/c.calf" ;;
encode-scene-exr)
  textured_obj ok.png
  "$bin/calf-capture" --scene "$work/model.obj" --export-scene "$work/scene" --frames 1 \
    --quiet >/dev/null 2>&1 || broken "the scene could not be exported"
  for t in "$work"/scene/textures/*.png; do cp "$work/attribute.exr" "$t"; done
  run "$bin/calf-encode" --mode mesh "$work/scene" -o "$work/c.calf" ;;
# calf-encode on a capture set: a manifest declaring face size 16384 with a matching header and
# no pixels (the budget, from the manifest, before a frame is allocated), and a set whose image
# is attribute.exr
encode-lightfield-face-size) run "$bin/calf-encode" "$work/set" -o "$work/c.calf" ;;
encode-analysis-face-size) run "$bin/calf-encode" --analysis-only "$work/set" -o "$work/c.calf" ;;
encode-tiles-face-size) run "$bin/calf-encode" --mode tiles "$work/set" -o "$work/c.calf" ;;
encode-lightfield-exr) run "$bin/calf-encode" "$work/set_exr" -o "$work/c.calf" ;;
*)
  echo "hostile_images.sh: unknown case $name" >&2
  exit 98
  ;;
esac
[ -e "$work/c.calf" ] && broken "an output was written"
[ -e "$work/out/manifest.json" ] && broken "an output was written"
# GNU time writes "Command exited with non-zero status N" first: the figures are the last line.
figures=$(tail -n 1 "$work/time")
kb=${figures% *}
seconds=${figures#* }
base=$(tail -n 1 "$work/time-base")
base_kb=${base% *}
base_s=${base#* }
[ -n "$seconds" ] && [ -n "$base_s" ] || broken "no time measured"
if [ "$kb" -gt $((base_kb + max_kb)) ]; then
  broken "peak resident set $kb KB, more than $max_kb KB over the start-up's $base_kb KB"
fi
if awk -v s="$seconds" -v b="$base_s" -v m="$max_s" 'BEGIN { exit !(s > b + m) }'; then
  broken "took $seconds s, more than $max_s s over the start-up's $base_s s"
fi
exit $rc
