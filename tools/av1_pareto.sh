#!/bin/sh
# Bytes against PSNR of calf's colour codings and x265, one panel per scene, from the lines
# `bench-lightfield_table1 --video-peers --av1-crf N ... --csv FILE` appends (docs/ENCODER.md
# "AV1 colour"): BC (one point), the AV1 mode at each CRF (a curve), and x265 matched to each.
#
#   tools/av1_pareto.sh FILE.csv OUT.png
#
# Needs gnuplot (pngcairo, else its libgd png terminal).
set -eu
if [ $# -ne 2 ]; then
  echo "usage: tools/av1_pareto.sh FILE.csv OUT.png" >&2
  exit 2
fi
csv=$1
out=$2
command -v gnuplot >/dev/null || { echo "av1_pareto: gnuplot is not installed" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The scenes in the order they first appear; per scene one data file per series:
# x = colour bytes (KiB), y = PSNR (dB).
scenes=$(awk -F, '!seen[$1]++ { print $1 }' "$csv")
n=0
for s in $scenes; do
  n=$((n + 1))
  awk -F, -v s="$s" '$1 == s && $4 !~ /^AV1/ { print $6 / 1024, $5 }' "$csv" >"$tmp/$n.bc"
  awk -F, -v s="$s" '$1 == s && $4 ~ /^AV1/ { print $6 / 1024, $5 }' "$csv" | sort -n >"$tmp/$n.av1"
  awk -F, -v s="$s" '$1 == s && $8 > 0 { print $8 / 1024, $7 }' "$csv" | sort -n >"$tmp/$n.x265"
  awk -F, -v s="$s" '$1 == s { print $2 "^2 faces, " $3 " views"; exit }' "$csv" >"$tmp/$n.title"
done
[ "$n" -gt 0 ] || { echo "av1_pareto: $csv holds no rows" >&2; exit 1; }

cols=$(( n < 4 ? n : 4 ))
rows=$(( (n + cols - 1) / cols ))
term="pngcairo size $((cols * 360)),$((rows * 300)) font 'DejaVu Sans,9'"
gnuplot -e "set terminal pngcairo" >/dev/null 2>&1 || term="png size $((cols * 360)),$((rows * 300))"
{
  echo "set terminal $term"
  echo "set output '$out'"
  echo "set multiplot layout $rows,$cols"
  echo "set logscale x"
  echo "set xlabel 'colour bytes (KiB)'"
  echo "set ylabel 'PSNR vs capture (dB)'"
  echo "set key bottom right"
  echo "set grid"
  i=0
  for s in $scenes; do
    i=$((i + 1))
    echo "set title '$s, $(cat "$tmp/$i.title")'"
    echo "plot '$tmp/$i.bc' with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'calf BC', \\"
    echo "  '$tmp/$i.av1' with linespoints pt 5 lc rgb '#d62728' title 'calf AV1 (CRFs)', \\"
    echo "  '$tmp/$i.x265' with linespoints pt 9 dt 2 lc rgb '#2ca02c' title 'x265 matched'"
  done
  echo "unset multiplot"
} >"$tmp/plot.gp"
gnuplot "$tmp/plot.gp"
echo "av1_pareto: wrote $out ($n scenes)"
