#!/usr/bin/env bash
# Runs calf's whole sharded pipeline without a cluster through GNU parallel (docs/FARM.md): the
# same tasks as tools/farm/slurm_submit.sh, stage after stage, --jobs at a time on this machine
# (or, with parallel's --sshlogin, on several machines sharing WORK). Stops at the first failed
# task with its exit status. The clip is WORK/clip.calf.
set -euo pipefail
if [[ "${1:-}" == "--help" || "${1:-}" == "-h" ]]; then
  cat <<USAGE
usage: tools/farm/parallel_run.sh --scene NAME --work DIR --view-count N [options] [-- parallel options]
$(source "$(dirname "$0")/farm_common.sh"; echo "$usage_common")
  -- ...                    the rest goes to every parallel call (default: --jobs 2)
Exit status: 0 the clip is written; else the failed task's; 2 usage.
USAGE
  exit 0
fi
# shellcheck source=farm_common.sh
source "$(dirname "$0")/farm_common.sh"
args=(); par=(--jobs 2)
while (( $# )); do
  if [[ "$1" == "--" ]]; then shift; par=("$@"); break; fi
  args+=("$1"); shift
done
parse_common "${args[@]}"
if (( ${#EXTRA[@]} )); then
  echo "parallel_run.sh: unknown option '${EXTRA[0]}' (see --help)" >&2
  exit 2
fi
run() { parallel --halt now,fail=1 "${par[@]}" "$TASK" "$WORK" "$1" ::: $(seq 0 $(( $2 - 1 ))); }
run capture "$CAPTURE_SHARDS"
"$TASK" "$WORK" prepare
run encode "$ENCODE_SHARDS"
"$TASK" "$WORK" merge
echo "$WORK/clip.calf"
