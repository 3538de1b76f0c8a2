#!/usr/bin/env bash
# Paper 000's budgets swept on one capture (Seurat's Figs. 13-14 as calf measures them): the
# triangle budget L_tris (--tiles-triangles), the average overdraw bound L_area (--tiles-overdraw)
# and the atlas size (--tiles-max-atlas), each with the other knobs at their defaults. Every point
# is a tiles build of EVAL_DIR/capture played against EVAL_DIR's ground truth at the capture
# viewpoints and on the eye path (the directories tools/tiles_eval.sh writes), so the figures are
# the same protocol as docs/TILES.md. Writes OUT/tiles_sweep.dat (one gnuplot data block per knob:
# value, triangles, bytes, atlas texels, build s, PSNR at the capture viewpoints, PSNR on the path)
# and, where gnuplot is installed, OUT/tiles_sweep.png.
# Usage: tools/tiles_sweep.sh BUILD_DIR EVAL_DIR OUT_DIR
# Environment: TRIANGLES, OVERDRAW, ATLAS (space-separated values to sweep; defaults below).
set -euo pipefail
BUILD=${1:?usage: tools/tiles_sweep.sh BUILD_DIR EVAL_DIR OUT_DIR}
EVAL=${2:?usage: tools/tiles_sweep.sh BUILD_DIR EVAL_DIR OUT_DIR}
OUT=${3:?usage: tools/tiles_sweep.sh BUILD_DIR EVAL_DIR OUT_DIR}
read -r -a triangles <<<"${TRIANGLES:-1000 2000 4000 8000 16000 72000}"
read -r -a overdraw <<<"${OVERDRAW:-1.2 1.4 1.6 2 3}"
read -r -a atlas <<<"${ATLAS:-256 512 1024 2048 8192}"
for d in capture gt-capture-views gt-path; do
  [ -d "$EVAL/$d" ] || { echo "tiles_sweep: $EVAL/$d missing (run tools/tiles_eval.sh first)" >&2; exit 2; }
done
mkdir -p "$OUT"
dat="$OUT/tiles_sweep.dat"
clip="$OUT/.sweep.calf"

# One point: prints "value triangles bytes texels build_s psnr_views psnr_path", or "value" and
# dashes when the build fails (a budget below what the view region needs: CALF-E253).
point() {
  local value=$1
  shift
  local t0 t1 log
  t0=$(date +%s.%N)
  if ! log=$("$BUILD"/calf-encode --mode tiles "$EVAL/capture" -o "$clip" "$@" 2>&1); then
    echo "tiles_sweep: $* -> ${log##*$'\n'}" >&2
    echo "# $value  build failed: ${log##*$'\n'}"
    return
  fi
  t1=$(date +%s.%N)
  local tris texels views path
  tris=$(sed -n 's/.*selection *[0-9]* tiles ([0-9]* of them the sky layer), \([0-9]*\) triangles.*/\1/p' <<<"$log")
  texels=$(sed -n 's/^ *texture *\([0-9]*\) tile texels.*/\1/p' <<<"$log")
  views=$("$BUILD"/calf-play "$clip" --headless --compare "$EVAL/gt-capture-views" 2>&1 |
    sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p')
  path=$("$BUILD"/calf-play "$clip" --headless --compare "$EVAL/gt-path" 2>&1 |
    sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p')
  awk -v v="$value" -v tr="$tris" -v b="$(stat -c %s "$clip")" -v tx="$texels" -v a="$t0" \
    -v z="$t1" -v pv="$views" -v pp="$path" \
    'BEGIN { printf "%s %s %s %s %.1f %s %s\n", v, tr, b, tx, z - a, pv, pp }'
}

{
  echo "# tools/tiles_sweep.sh $EVAL: value triangles bytes atlas_texels build_s psnr_capture_views psnr_path"
  echo "# L_tris (--tiles-triangles)"
  for v in "${triangles[@]}"; do point "$v" --tiles-triangles "$v"; done
  printf '\n\n# L_area (--tiles-overdraw)\n'
  for v in "${overdraw[@]}"; do point "$v" --tiles-overdraw "$v"; done
  printf '\n\n# atlas side (--tiles-max-atlas)\n'
  for v in "${atlas[@]}"; do point "$v" --tiles-max-atlas "$v"; done
} >"$dat"
rm -f "$clip"
cat "$dat"

if command -v gnuplot >/dev/null; then
  gnuplot <<EOF
set terminal pngcairo size 1200,400 noenhanced
set output '$OUT/tiles_sweep.png'
set multiplot layout 1,3 title "tiles on $(basename "$EVAL"): PSNR at the capture viewpoints and on the path"
set grid
set ylabel "mean PSNR (dB)"
set key bottom right
set logscale x
set xlabel "L_tris (triangles budget)"
plot '$dat' index 0 using 1:6 with linespoints pt 7 title 'capture viewpoints', \
     '' index 0 using 1:7 with linespoints pt 5 title 'path'
unset logscale x
set xlabel "L_area (average overdraw bound)"
plot '$dat' index 1 using 1:6 with linespoints pt 7 title 'capture viewpoints', \
     '' index 1 using 1:7 with linespoints pt 5 title 'path'
set logscale x 2
set xlabel "largest atlas side (texels)"
plot '$dat' index 2 using 1:6 with linespoints pt 7 title 'capture viewpoints', \
     '' index 2 using 1:7 with linespoints pt 5 title 'path'
unset multiplot
EOF
  echo "tiles_sweep: $OUT/tiles_sweep.png" >&2
fi
