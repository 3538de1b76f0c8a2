#!/usr/bin/env bash
# Submits calf's whole sharded pipeline to Slurm as job arrays chained by dependencies
# (docs/FARM.md): capture shards -> join + analysis -> encode shards -> merge. Prints the four job
# ids (one line: capture prepare encode merge) on stdout and returns at once; the clip appears as
# WORK/clip.calf when the merge job completes. A failed task cancels every later stage
# (afterok dependencies, --kill-on-invalid-dep).
set -euo pipefail
if [[ "${1:-}" == "--help" || "${1:-}" == "-h" ]]; then
  cat <<USAGE
usage: tools/farm/slurm_submit.sh --scene NAME --work DIR --view-count N [options] [-- sbatch options]
$(source "$(dirname "$0")/farm_common.sh"; echo "$usage_common")
  -- ...                    the rest goes to every sbatch (e.g. --partition=render --mem=4G)
Needs sbatch on PATH (and SLURM_CONF when the cluster's config is not the default); WORK must be
on a file system every node sees. Exit status: 0 submitted; 1 sbatch failed; 2 usage.
USAGE
  exit 0
fi
# shellcheck source=farm_common.sh
source "$(dirname "$0")/farm_common.sh"
args=(); sbatch_extra=()
while (( $# )); do
  if [[ "$1" == "--" ]]; then shift; sbatch_extra=("$@"); break; fi
  args+=("$1"); shift
done
parse_common "${args[@]}"
if (( ${#EXTRA[@]} )); then
  echo "slurm_submit.sh: unknown option '${EXTRA[0]}' (see --help)" >&2
  exit 2
fi
mkdir -p "$WORK/logs"
sb() { sbatch --parsable --kill-on-invalid-dep=yes "${sbatch_extra[@]}" "$@"; }
capture=$(sb --job-name=calf-capture --array=0-$((CAPTURE_SHARDS - 1)) \
  --output="$WORK/logs/capture-%a.log" "$TASK" "$WORK" capture)
prepare=$(sb --job-name=calf-prepare --dependency=afterok:"$capture" \
  --output="$WORK/logs/prepare.log" "$TASK" "$WORK" prepare)
encode=$(sb --job-name=calf-encode --dependency=afterok:"$prepare" \
  --array=0-$((ENCODE_SHARDS - 1)) --output="$WORK/logs/encode-%a.log" "$TASK" "$WORK" encode)
merge=$(sb --job-name=calf-merge --dependency=afterok:"$encode" \
  --output="$WORK/logs/merge.log" "$TASK" "$WORK" merge)
echo "$capture $prepare $encode $merge"
