#!/usr/bin/env bash
# calf-play's light-field march and blend options reach both renderers: each option below, given
# a value other than its default, changes the frames calf-play writes (EXR, so that no change
# hides in 8-bit rounding) of a tiny clip along its ground truth's eye path, with the GL renderer
# (OSMesa) and the CPU reference alike; the same command without it writes the default's frames.
# --quality writes the frames of the options it stands for, under any of them given beside it.
# Usage: play_render_options.sh CALF_PLAY CLIP EYE_PATH WORK_DIR
set -euo pipefail
play=$1 clip=$2 eye=$3 work=$4
rm -rf "$work"
mkdir -p "$work"
render() {  # renderer name options... -> frames in $work/renderer-name
  local renderer=$1 name=$2
  shift 2
  "$play" "$clip" --headless --eye-path "$eye" --renderer "$renderer" --format exr \
    --out "$work/$renderer-$name" "$@" > /dev/null
}
failed=0
for renderer in gl cpu; do
  render "$renderer" default
  render "$renderer" default-again
  if ! diff -r "$work/$renderer-default" "$work/$renderer-default-again" > /dev/null; then
    echo "play_render_options: $renderer: two runs with the defaults differ" >&2
    exit 1
  fi
  render "$renderer" hints4 --hints 4
  # name|options: the hint options with 4 hint views, where vetoes and their margin decide
  for case in "cam-decay|--cam-decay 2" "depth-decay|--depth-decay 5" "blend-views|--blend-views 2" \
              "hint-vetoes|--hints 4 --hint-vetoes 0" \
              "hint-margin|--hints 4 --hint-margin 8"; do
    name=${case%%|*}
    read -r -a options <<< "${case#*|}"
    render "$renderer" "$name" "${options[@]}"
    reference=default
    # The hint options against 4 hint views at the defaults of the rest
    case $name in hint-*) reference=hints4 ;; esac
    if diff -r "$work/$renderer-$reference" "$work/$renderer-$name" > /dev/null; then
      echo "play_render_options: $renderer: ${case#*|} leaves the frames as they are" >&2
      failed=1
    else
      echo "play_render_options: $renderer: ${case#*|} changes the frames"
    fi
  done
  # --quality is its six knobs, and an option given beside it keeps its own value.
  quality=(--steps 128 --hints 4 --hint-vetoes 0 --blend-views 3 --colour-sharpen 0.2)
  render "$renderer" quality --quality
  render "$renderer" quality-explicit "${quality[@]}" --supersample 4
  render "$renderer" quality-ss2 --quality --supersample 2
  render "$renderer" quality-ss2-explicit "${quality[@]}" --supersample 2
  for pair in quality:quality-explicit quality-ss2:quality-ss2-explicit; do
    if ! diff -r "$work/$renderer-${pair%%:*}" "$work/$renderer-${pair#*:}" > /dev/null; then
      echo "play_render_options: $renderer: ${pair%%:*} differs from its options given one by one" >&2
      failed=1
    fi
  done
  for other in default quality-ss2; do
    if diff -r "$work/$renderer-quality" "$work/$renderer-$other" > /dev/null; then
      echo "play_render_options: $renderer: --quality renders the frames of $other" >&2
      failed=1
    fi
  done
  echo "play_render_options: $renderer: --quality is its options, and --supersample beside it counts"
done
exit $failed
