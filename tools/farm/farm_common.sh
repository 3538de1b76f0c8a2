# Shared by slurm_submit.sh and parallel_run.sh: option parsing and WORK/farm.env.
# shellcheck shell=bash
usage_common='  --bin DIR                 calf binaries (calf-capture, calf-encode, calf-merge); default build/rel
  --scene NAME|FILE         scene to capture (calf-capture --scene); required
  --work DIR                shared working directory (capture/, analysis.calf, shards/, clip.calf); required
  --view-count N            viewpoints of the rig (calf-capture --list-scenes); required
  --face-size N             cube face size; default 256
  --frames N                frames; default 30
  --capture-views N         views per capture shard; default 1
  --capture-frames N        frames per capture shard; default all
  --encode-views N          views per encode shard; default 1
  --encode-frames N         frames per encode shard, a multiple of the --segment-frames given in
                            --encode-opts; default all (no segments needed)
  --threads N               threads per task (calf --threads; 0 = all cores); default 1
  --capture-opts "..."      more calf-capture options (e.g. "--spp 16"); default none
  --encode-opts "..."       calf-encode options of the analysis (e.g. "--depth-format pred16")'
parse_common() {
  BIN=build/rel; SCENE=; WORK=; VIEW_COUNT=; FACE_SIZE=256; FRAMES=30; CAPTURE_VIEWS=1
  CAPTURE_FRAMES=; ENCODE_VIEWS=1; ENCODE_FRAMES=; THREADS=1; CAPTURE_OPTS=; ENCODE_OPTS=; EXTRA=()
  while (( $# )); do
    case "$1" in
      --bin) BIN=$2; shift 2 ;;
      --scene) SCENE=$2; shift 2 ;;
      --work) WORK=$2; shift 2 ;;
      --view-count) VIEW_COUNT=$2; shift 2 ;;
      --face-size) FACE_SIZE=$2; shift 2 ;;
      --frames) FRAMES=$2; shift 2 ;;
      --capture-views) CAPTURE_VIEWS=$2; shift 2 ;;
      --capture-frames) CAPTURE_FRAMES=$2; shift 2 ;;
      --encode-views) ENCODE_VIEWS=$2; shift 2 ;;
      --encode-frames) ENCODE_FRAMES=$2; shift 2 ;;
      --threads) THREADS=$2; shift 2 ;;
      --capture-opts) CAPTURE_OPTS=$2; shift 2 ;;
      --encode-opts) ENCODE_OPTS=$2; shift 2 ;;
      *) EXTRA+=("$1"); shift ;;
    esac
  done
  if [[ -z "$SCENE" || -z "$WORK" || -z "$VIEW_COUNT" ]]; then
    echo "$(basename "$0"): --scene, --work and --view-count are required (see --help)" >&2
    exit 2
  fi
  for n in "$VIEW_COUNT" "$FACE_SIZE" "$FRAMES" "$CAPTURE_VIEWS" "${CAPTURE_FRAMES:-1}" \
           "$ENCODE_VIEWS" "${ENCODE_FRAMES:-1}"; do
    if ! [[ "$n" =~ ^[1-9][0-9]*$ ]]; then
      echo "$(basename "$0"): '$n' is not a positive count (see --help)" >&2
      exit 2
    fi
  done
  CAPTURE_FRAMES=${CAPTURE_FRAMES:-$FRAMES}
  ENCODE_FRAMES=${ENCODE_FRAMES:-$FRAMES}
  BIN=$(cd "$BIN" && pwd)
  mkdir -p "$WORK"
  WORK=$(cd "$WORK" && pwd)
  CAPTURE_SHARDS=$(( ((VIEW_COUNT + CAPTURE_VIEWS - 1) / CAPTURE_VIEWS) *
                     ((FRAMES + CAPTURE_FRAMES - 1) / CAPTURE_FRAMES) ))
  ENCODE_SHARDS=$(( ((VIEW_COUNT + ENCODE_VIEWS - 1) / ENCODE_VIEWS) *
                    ((FRAMES + ENCODE_FRAMES - 1) / ENCODE_FRAMES) ))
  {
    printf 'CALF_BIN=%q\nSCENE=%q\nVIEW_COUNT=%q\nFACE_SIZE=%q\nFRAMES=%q\n' \
      "$BIN" "$SCENE" "$VIEW_COUNT" "$FACE_SIZE" "$FRAMES"
    printf 'CAPTURE_VIEWS_PER_SHARD=%q\nCAPTURE_FRAMES_PER_SHARD=%q\nENCODE_VIEWS_PER_SHARD=%q\n' \
      "$CAPTURE_VIEWS" "$CAPTURE_FRAMES" "$ENCODE_VIEWS"
    printf 'ENCODE_FRAMES_PER_SHARD=%q\n' "$ENCODE_FRAMES"
    printf 'THREADS=%q\nCAPTURE_OPTS=%q\nENCODE_OPTS=%q\n' "$THREADS" "$CAPTURE_OPTS" "$ENCODE_OPTS"
  } > "$WORK/farm.env"
  TASK="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/calf_farm_task.sh"
}
