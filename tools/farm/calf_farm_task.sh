#!/usr/bin/env bash
# One task of calf's sharded pipeline (docs/FARM.md): run by tools/farm/slurm_submit.sh as Slurm
# array tasks and by tools/farm/parallel_run.sh through GNU parallel.
#
#   calf_farm_task.sh WORK STAGE [INDEX]
#
# WORK holds farm.env (written by the submitters: binaries, scene, sizes, shard sizes, options).
# STAGE is capture (render capture shard INDEX), prepare (join the capture shards, run the
# analysis pass), encode (code view shard INDEX) or merge (join the shards into WORK/clip.calf).
# INDEX defaults to $SLURM_ARRAY_TASK_ID. Exit status: the calf command's.
set -euo pipefail
work=${1:?usage: calf_farm_task.sh WORK STAGE [INDEX]}
stage=${2:?usage: calf_farm_task.sh WORK STAGE [INDEX]}
index=${3:-${SLURM_ARRAY_TASK_ID:-0}}
# shellcheck source=/dev/null
source "$work/farm.env"

ceil_div() { echo $(( ($1 + $2 - 1) / $2 )); }
# "a-b" of shard s of size n over count items.
range_of() {
  local s=$1 n=$2 count=$3 a b
  a=$(( s * n )); b=$(( a + n - 1 )); (( b >= count )) && b=$(( count - 1 ))
  echo "$a-$b"
}
# Test hook (tests/integration/slurm_pipeline_test.sh): CALF_FARM_FAIL=stage:index makes that
# task fail as a crashed or killed job would.
if [[ "${CALF_FARM_FAIL:-}" == "$stage:$index" ]]; then
  echo "calf_farm_task: $stage $index: failing on purpose (CALF_FARM_FAIL)" >&2
  exit 1
fi

# Peak memory and wall time of each step on stderr (GNU time when installed).
measure() {
  if [[ -x /usr/bin/time ]]; then
    /usr/bin/time -f "calf_farm_task: $stage $index: %e s wall, %M KiB peak RSS" "$@"
  else
    "$@"
  fi
}

case "$stage" in
  capture)
    view_shards=$(ceil_div "$VIEW_COUNT" "$CAPTURE_VIEWS_PER_SHARD")
    vs=$(( index % view_shards )); fs=$(( index / view_shards ))
    measure "$CALF_BIN/calf-capture" --scene "$SCENE" --out "$work/capture" \
      --face-size "$FACE_SIZE" --frames "$FRAMES" --threads "$THREADS" --quiet \
      --views "$(range_of "$vs" "$CAPTURE_VIEWS_PER_SHARD" "$VIEW_COUNT")" \
      --frame-range "$(range_of "$fs" "$CAPTURE_FRAMES_PER_SHARD" "$FRAMES")" $CAPTURE_OPTS
    ;;
  prepare)
    "$CALF_BIN/calf-capture" --join --out "$work/capture" --quiet
    # shellcheck disable=SC2086
    measure "$CALF_BIN/calf-encode" "$work/capture" --analysis-only -o "$work/analysis.calf" \
      --threads "$THREADS" -q $ENCODE_OPTS
    ;;
  encode)
    mkdir -p "$work/shards"
    view_shards=$(ceil_div "$VIEW_COUNT" "$ENCODE_VIEWS_PER_SHARD")
    vs=$(( index % view_shards )); fs=$(( index / view_shards ))
    measure "$CALF_BIN/calf-encode" "$work/capture" --analysis "$work/analysis.calf" \
      --views "$(range_of "$vs" "$ENCODE_VIEWS_PER_SHARD" "$VIEW_COUNT")" \
      --frame-range "$(range_of "$fs" "$ENCODE_FRAMES_PER_SHARD" "$FRAMES")" \
      -o "$work/shards/shard-$(printf %05d "$index").calf" --threads "$THREADS" -q
    ;;
  merge)
    shards=$(( $(ceil_div "$VIEW_COUNT" "$ENCODE_VIEWS_PER_SHARD") *
               $(ceil_div "$FRAMES" "$ENCODE_FRAMES_PER_SHARD") ))
    files=()
    for (( i = 0; i < shards; ++i )); do files+=("$work/shards/shard-$(printf %05d "$i").calf"); done
    measure "$CALF_BIN/calf-merge" --analysis "$work/analysis.calf" -o "$work/clip.calf" -q \
      "${files[@]}"
    ;;
  *)
    echo "calf_farm_task: unknown stage '$stage' (capture, prepare, encode, merge)" >&2
    exit 2
    ;;
esac
