#!/usr/bin/env bash
# Compares this tree with another git revision byte for byte, on a small clip of every track kind:
# builds REV in a temporary git worktree (Release, through ccache when it is installed), makes the
# inputs once with this tree's calf-capture (the interior scene's capture set and eye path; the
# spheres scene's scene file, surfel candidates and walk), encodes a lightfield, tiles, mesh and
# surfels clip with both builds and plays each headless along its eye path with both renderers
# (GL through OSMesa, and the CPU reference), frames written as PNG and EXR. One line per kind,
# then a summary line; exit 0 when every clip and frame is identical, 1 when one differs, 2 for a
# usage error.
#
# Usage: tools/compare_frames.sh REV [WORK_DIR]
#   REV       any git revision (a commit, a branch, HEAD~3)
#   WORK_DIR  scratch directory, removed first (default build/compare-frames); REV's worktree is
#             WORK_DIR/src, built in WORK_DIR/src/build/release (the same depth below the source
#             as this tree's build, so ccache hits across both) and removed at the end unless
#             CALF_COMPARE_KEEP=1.
# Environment: CALF_COMPARE_BUILD, this tree's Release build directory (default build/release,
# configured and built when needed).
set -euo pipefail
usage() {
  echo "usage: tools/compare_frames.sh REV [WORK_DIR]" >&2
  exit 2
}
if [ $# -lt 1 ] || [ $# -gt 2 ]; then usage; fi
cd "$(dirname "$0")/.."
ROOT=$PWD
REV_SHA=$(git rev-parse --verify --quiet "$1^{commit}") || {
  echo "compare_frames: $1 is not a git revision" >&2
  exit 2
}
WORK=$(realpath -m "${2:-build/compare-frames}")
THIS_BUILD=$(realpath -m "${CALF_COMPARE_BUILD:-build/release}")
TARGETS=(calf-capture calf-encode calf-play)
step() { echo "compare_frames: $*" >&2; }

launcher=()
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(dirname "$ROOT")} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
build() {  # SOURCE BUILD_DIR
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
  cmake --build "$2" --target "${TARGETS[@]}" >"$2/compare_frames_build.log" 2>&1 || {
    tail -n 30 "$2/compare_frames_build.log" >&2
    echo "compare_frames: the build in $2 failed" >&2
    exit 1
  }
}

if [ -e "$WORK/src" ]; then git worktree remove --force "$WORK/src" 2>/dev/null || true; fi
rm -rf "$WORK"
mkdir -p "$WORK"
cleanup() {
  if [ "${CALF_COMPARE_KEEP:-0}" != 1 ] && [ -e "$WORK/src" ]; then
    git -C "$ROOT" worktree remove --force "$WORK/src" || true
  fi
}
trap cleanup EXIT
git worktree add --quiet --detach "$WORK/src" "$REV_SHA"
step "building this tree in $THIS_BUILD"
build "$ROOT" "$THIS_BUILD"
step "building ${REV_SHA:0:12} in $WORK/src/build/release"
build "$WORK/src" "$WORK/src/build/release"

# The inputs, once, with this tree's calf-capture: both builds read the same files.
IN=$WORK/inputs
CAPTURE=$THIS_BUILD/calf-capture
step "making the inputs in $IN"
"$CAPTURE" --scene interior --face-size 16 --frames 2 --quiet --out "$IN/cap"
"$CAPTURE" --scene interior --ground-truth --gt-size 24x24 --frames 2 --quiet --out "$IN/gt" \
  --ao-samples 0 --max-bounces 0 --spp 1 --no-noise-floor
"$CAPTURE" --scene spheres --frames 2 --export-scene "$IN/scene" --quiet
"$CAPTURE" --scene "$IN/scene" --surfel-candidates "$IN/surfels.cand" --surfel-resolution 64 \
  --quiet
"$CAPTURE" --scene spheres --frames 2 --ground-truth --gt-size 48x32 --ao-samples 0 \
  --max-bounces 0 --spp 1 --no-noise-floor --quiet --out "$IN/walk"

# encode_args KIND: sets `args` to calf-encode's arguments for KIND's clip; eye_path KIND.
encode_args() {
  case $1 in
    lightfield) args=("$IN/cap" --cell 8) ;;
    tiles) args=(--mode tiles "$IN/cap" --tiles-triangles 2000) ;;
    mesh) args=(--mode mesh "$IN/scene") ;;
    surfels) args=(--mode surfels "$IN/scene" --surfel-candidates "$IN/surfels.cand" --surfels 1000) ;;
  esac
}
eye_path() {
  case $1 in
    lightfield | tiles) echo "$IN/gt/eye_path.json" ;;
    mesh | surfels) echo "$IN/walk/eye_path.json" ;;
  esac
}

# run_side SIDE BUILD KIND: SIDE's clip of KIND and its frames under $WORK/SIDE/KIND.
run_side() {
  local dir=$WORK/$1/$3 renderer args
  mkdir -p "$dir"
  encode_args "$3"
  "$2"/calf-encode "${args[@]}" -o "$dir/clip.calf" --quiet >"$dir/encode.log" 2>&1 || {
    echo "encode failed: $(tail -n 1 "$dir/encode.log")"
    return
  }
  for renderer in gl cpu; do
    "$2"/calf-play "$dir/clip.calf" --headless --eye-path "$(eye_path "$3")" --renderer "$renderer" \
      --format both --out "$dir/$renderer" >"$dir/play_$renderer.log" 2>&1 || {
      echo "play ($renderer) failed: $(tail -n 1 "$dir/play_$renderer.log")"
      return
    }
  done
}

differences=0
for kind in lightfield tiles mesh surfels; do
  step "$kind"
  fail_this=$(run_side this "$THIS_BUILD" "$kind")
  fail_rev=$(run_side rev "$WORK/src/build/release" "$kind")
  a=$WORK/this/$kind b=$WORK/rev/$kind
  problems=()
  [ -z "$fail_this" ] || problems+=("this tree: $fail_this")
  [ -z "$fail_rev" ] || problems+=("${REV_SHA:0:12}: $fail_rev")
  counts=""
  if [ ${#problems[@]} -eq 0 ]; then
    cmp -s "$a/clip.calf" "$b/clip.calf" || problems+=("clip.calf differs")
    for renderer in gl cpu; do
      if ! diff -q <(cd "$a/$renderer" && ls) <(cd "$b/$renderer" && ls) >/dev/null; then
        problems+=("$renderer: other frame files")
        continue
      fi
      n=0
      for f in "$a/$renderer"/*; do
        cmp -s "$f" "$b/$renderer/${f##*/}" || problems+=("$renderer ${f##*/} differs")
        n=$((n + 1))
      done
      counts+="${counts:+,} $renderer $n files"
    done
  fi
  if [ ${#problems[@]} -eq 0 ]; then
    echo "$kind: identical (clip $(stat -c %s "$a/clip.calf") bytes; frames:$counts)"
  else
    differences=$((differences + 1))
    listed=$(printf '%s; ' "${problems[@]:0:4}")
    [ ${#problems[@]} -le 4 ] || listed+="... "
    echo "$kind: DIFFERENT (${listed%; })"
  fi
done
if [ "$differences" -eq 0 ]; then
  echo "compare_frames: every kind identical to ${REV_SHA:0:12}"
  exit 0
fi
echo "compare_frames: $differences kind(s) differ from ${REV_SHA:0:12} (files in $WORK)"
exit 1
