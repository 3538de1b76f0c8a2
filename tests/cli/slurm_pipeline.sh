#!/usr/bin/env bash
# The sharded pipeline on a real Slurm (docs/FARM.md): starts a private single-node
# Slurm on localhost (munged, slurmctld, slurmd from Debian's packages, configured in a temp dir
# on free ports, run as root), submits tools/farm/slurm_submit.sh's job arrays (capture shards ->
# join + analysis -> encode shards -> merge) on a small scene, and checks
#   1. the merged clip is byte-identical to a one-machine calf-encode of the joined capture;
#   2. the same with frame-range encode shards and closed segments (--segment-frames);
#   3. a pipeline with a failing encode shard fails: that task FAILED, the merge never ran, no clip.
# The daemons are always stopped (trap). Bounded: every wait has a timeout. Exit 0 pass, 1 fail,
# 77 skip (not root: slurmd must run as root here). Usage: slurm_pipeline.sh BIN_DIR SOURCE_DIR
set -uo pipefail
bin=${1:?usage: slurm_pipeline.sh BIN_DIR SOURCE_DIR}
src=${2:?usage: slurm_pipeline.sh BIN_DIR SOURCE_DIR}
bin=$(cd "$bin" && pwd); src=$(cd "$src" && pwd)
say() { echo "slurm_pipeline: $*"; }
fail() { say "FAIL: $*"; exit 1; }

if [[ $(id -u) != 0 ]]; then
  say "SKIP: needs root (slurmd and munged run as root in this test)"
  exit 77
fi
for c in munged slurmctld slurmd sbatch scontrol sinfo; do
  command -v "$c" >/dev/null ||
    fail "$c is missing: tools/setup.sh installs slurmctld, slurmd, slurm-client and munge"
done

T=$(mktemp -d /tmp/calf-slurm.XXXXXX)
pids=()
cleanup() {
  local rc=$?
  # Stopping the watchdog ends its sleep, after which it may still send its TERM: ignored from
  # here on (that race once turned a PASS into "FAIL: interrupted" as the test exited).
  trap '' INT TERM HUP
  if [[ -n ${watchdog:-} ]]; then pkill -P "$watchdog" 2>/dev/null; kill "$watchdog" 2>/dev/null; fi
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  [[ -f $T/munge/munged.pid ]] && kill "$(cat "$T/munge/munged.pid")" 2>/dev/null
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$p" 2>/dev/null
  done
  if (( rc != 0 )); then
    for f in "$T"/slurmctld.log "$T"/slurmd.log "$T"/munge/munged.log "$T"/work*/logs/*.log; do
      [[ -f $f ]] && { echo "--- $f (last lines)"; tail -n 8 "$f"; }
    done
  fi
  rm -rf "$T"
  exit "$rc"
}
trap cleanup EXIT
trap 'say "FAIL: interrupted or past the 240 s watchdog"; exit 1' INT TERM HUP
# A watchdog below ctest's 300 s timeout: ctest's kill would skip the trap, and munged (which
# daemonizes) would outlive the test.
( sleep 240; kill -TERM $$ ) > /dev/null 2>&1 < /dev/null &
watchdog=$!

# munged: its own key, socket and files (never the system's).
mkdir -p "$T/munge" "$T/state" "$T/spool"
chmod 700 "$T/munge"
head -c 1024 /dev/urandom > "$T/munge/munge.key"
chmod 400 "$T/munge/munge.key"
munged --force --socket="$T/munge/munge.sock" --key-file="$T/munge/munge.key" \
  --pid-file="$T/munge/munged.pid" --log-file="$T/munge/munged.log" \
  --seed-file="$T/munge/seed" --num-threads=2 || fail "munged did not start"

# Two free TCP ports next to each other (not listening in /proc/net/tcp*).
port_free() {
  local hex
  hex=$(printf ':%04X ' "$1")
  ! grep -qi "$hex" /proc/net/tcp /proc/net/tcp6 2>/dev/null
}
port=0
for _ in $(seq 50); do
  p=$(( 20000 + RANDOM % 30000 ))
  if port_free "$p" && port_free $(( p + 1 )); then port=$p; break; fi
done
(( port )) || fail "no free port pair found"
host=$(hostname -s)
cat > "$T/slurm.conf" <<CONF
ClusterName=calftest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$(( port + 1 ))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.sock
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=calf Nodes=ALL Default=YES MaxTime=10 State=UP
CONF
export SLURM_CONF=$T/slurm.conf
slurmctld -D -f "$SLURM_CONF" > "$T/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" > "$T/slurmd.out" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 60); do
  if [[ $(timeout 5 sinfo -h -o %t 2>/dev/null) == idle* ]]; then up=1; break; fi
  sleep 0.5
done
(( up )) || fail "Slurm did not come up within 30 s (logs below)"
say "Slurm up on 127.0.0.1:$port ($(nproc) CPUs)"

# The state of a job (the first task's for an array when asked for one task).
state_of() { timeout 5 scontrol show job "$1" -o 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -n1 | cut -d= -f2; }
# Waits until job $1 is in a final state; prints it. 120 s at most.
wait_job() {
  local s
  for _ in $(seq 240); do
    s=$(state_of "$1")
    case "$s" in
      COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)
        echo "$s"; return 0 ;;
    esac
    sleep 0.5
  done
  echo "TIMEOUT_WAITING"
}

scene=mirror-box; views=9; face=8; frames=4
common=(--bin "$bin" --scene "$scene" --view-count "$views" --face-size "$face" --frames "$frames"
        --capture-views 3 --capture-frames 2 --threads 1 --capture-opts "--spp 1 --ao-samples 1")

# 1. View shards.
start=$(date +%s)
ids=$("$src/tools/farm/slurm_submit.sh" "${common[@]}" --work "$T/work1" --encode-views 3) ||
  fail "slurm_submit.sh failed"
read -r _ _ _ merge <<< "$ids"
s=$(wait_job "$merge")
[[ $s == COMPLETED ]] || fail "view-shard pipeline: merge job $merge ended $s"
"$bin/calf-encode" "$T/work1/capture" -o "$T/work1/one-machine.calf" -q --threads 1 \
  2> "$T/one-machine1.log" ||
  fail "one-machine encode failed"
cmp "$T/work1/clip.calf" "$T/work1/one-machine.calf" ||
  fail "the merged clip differs from the one-machine encode"
say "view shards: 6 capture + 3 encode tasks, merged clip byte-identical ($(stat -c %s "$T/work1/clip.calf") bytes) in $(( $(date +%s) - start )) s"

# 2. Frame-range shards with closed segments of 2 frames.
start=$(date +%s)
seg=(--segment-frames 2 --depth-keyframe-interval 2)
ids=$("$src/tools/farm/slurm_submit.sh" "${common[@]}" --work "$T/work2" --encode-views 5 \
      --encode-frames 2 --encode-opts "${seg[*]}") || fail "slurm_submit.sh failed"
read -r _ _ _ merge <<< "$ids"
s=$(wait_job "$merge")
[[ $s == COMPLETED ]] || fail "frame-shard pipeline: merge job $merge ended $s"
"$bin/calf-encode" "$T/work2/capture" -o "$T/work2/one-machine.calf" -q --threads 1 "${seg[@]}" \
  2> "$T/one-machine2.log" ||
  fail "one-machine segmented encode failed"
cmp "$T/work2/clip.calf" "$T/work2/one-machine.calf" ||
  fail "the merged frame-shard clip differs from the one-machine encode"
say "frame shards: 4 encode tasks (2 view x 2 frame ranges), byte-identical in $(( $(date +%s) - start )) s"

# 3. A failing encode shard fails the pipeline.
ids=$(CALF_FARM_FAIL=encode:1 "$src/tools/farm/slurm_submit.sh" "${common[@]}" --work "$T/work3" \
      --encode-views 3) || fail "slurm_submit.sh failed"
read -r _ _ encode merge <<< "$ids"
s=$(wait_job "$merge")
[[ $s == CANCELLED ]] || fail "with encode task 1 failing, the merge job ended '$s', not CANCELLED"
task=$(state_of "${encode}_1")
[[ $task == FAILED ]] || fail "the failing encode task ended '$task', not FAILED"
[[ ! -e $T/work3/clip.calf ]] || fail "a clip was written although a shard failed"
say "a failing encode shard: task FAILED, merge CANCELLED, no clip"
say "PASS"
