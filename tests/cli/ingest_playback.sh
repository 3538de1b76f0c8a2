#!/usr/bin/env bash
# The acceptance of calf-ingest, end to end on a built-in scene (interior, faces of 16,
# one frame, ground truth 24 x 24):
#  - the native capture, rewritten as a Seurat capture (EYE_Z and RAY_DEPTH, row-major matrices,
#    Unity's face order, a separate depth EXR with channel R; tests/capture/foreign_from_capture),
#    ingested, encoded and played, is within 0.1 dB PSNR of the native capture played alike;
#  - equirectangular sets resampled from a native capture with faces of 64 (16 colour samples per
#    pixel, like an anti-aliased renderer's box) at two equal texel densities, ingested with the
#    default filter at faces of 16, play within 1 dB of the native capture with faces of 16:
#    64 x 32 (as many pixels around the horizon as the cube's 4 x 16 texels) and 56 x 28 (as many
#    pixels in all as the cube's 6 x 16^2 texels, 56 = round(sqrt(12) x 16)). 50 x 25
#    (round(pi x 16), the density of a face's centre, the default face-size rule) is printed only:
#    the cube is denser than that image almost everywhere off its face centres.
# Captures are calf-capture's converged defaults. Measured (format/CAPTURE.md "Ingest"): native
# 27.10 dB; equirect 64 wide 26.79, 56 wide 26.45, 50 wide 24.92; bilinear without sharpening
# (calf-ingest --filter bilinear --sharpen 0, the first version) 25.63 / 24.11 at 64 / 50.
# Usage: ingest_playback.sh CALF_CAPTURE CALF_ENCODE CALF_PLAY CALF_INGEST FOREIGN WORK_DIR
set -euo pipefail
capture=$1 encode=$2 play=$3 ingest=$4 foreign=$5 work=$6
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$capture" --scene interior --face-size 16 --frames 1 --quiet --out cap
"$capture" --scene interior --face-size 64 --frames 1 --quiet --out cap64
"$capture" --scene interior --ground-truth --gt-size 24x24 --frames 1 --quiet --out gt
psnr() {  # clip -> mean PSNR of calf-play's CPU reference renderer against the ground truth
  "$play" "$1" --headless --compare gt --renderer cpu | sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p'
}
"$encode" cap -o native.calf --cell 8 --quiet
native=$(psnr native.calf)
status=0
check() {  # name clip tolerance
  local p
  p=$(psnr "$2")
  if awk -v a="$p" -v b="$native" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; then
    echo "ingest_playback: $1 $p dB, native $native dB (within $3 dB)"
  else
    echo "ingest_playback: FAIL $1 $p dB, native $native dB (more than $3 dB apart)"
    status=1
  fi
}
for depth in eye_z ray_depth; do
  "$foreign" seurat cap "seurat_$depth" "$depth"
  "$ingest" seurat --quiet "seurat_$depth/manifest.json" "ingested_$depth"
  "$encode" "ingested_$depth" -o "$depth.calf" --cell 8 --quiet
  check "seurat $depth" "$depth.calf" 0.1
done
for width in 64 56 50; do
  "$foreign" equirect cap64 "equirect$width" "$width"
  "$ingest" equirect --quiet --face-size 16 "equirect$width/equirect.json" "ingested_equirect$width"
  "$encode" "ingested_equirect$width" -o "equirect$width.calf" --cell 8 --quiet
done
check "equirect 64x32 (equal texels around the horizon)" equirect64.calf 1.0
check "equirect 56x28 (equal texels in all)" equirect56.calf 1.0
echo "ingest_playback: equirect 50x25 (a face centre's density) $(psnr equirect50.calf) dB, native $native dB (not checked)"
exit $status
