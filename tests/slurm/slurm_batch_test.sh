#!/usr/bin/env bash
# The batch on a real Slurm cluster: installs Debian's slurm-wlm and munge when missing, starts a
# one-node cluster on this machine (loopback only, every file in a temporary folder, nothing under
# /etc), submits scripts/slurm/batch.sbatch as a job array over shards, waits for it, merges the
# shards with `airtwin batch-merge` and compares the result with the same batch run unsharded on
# this machine: runs.csv byte for byte, the report but its wall-clock part, the plots. The daemons
# are stopped on exit, whatever happens.
#
# Usage: slurm_batch_test.sh AIRTWIN SOURCE_DIR     (ctest: label slurm)
# Exit: 0 pass, 1 fail, 77 skipped (not root: it installs packages and runs slurmd as root).
set -euo pipefail

airtwin=$1
src=$2
shards=4
seeds=4
scenarios=("$src/scenes/line.yaml" "$src/scenes/square.yaml")
t0=$EPOCHREALTIME
since() { awk -v now="$EPOCHREALTIME" -v then="$1" 'BEGIN { printf "%.1f", now - then }'; }
elapsed() { since "$t0"; }
say() { echo "slurm_batch_test [$(elapsed) s]: $*"; }
fail() { echo "slurm_batch_test: FAIL: $*" >&2; exit 1; }

if [ "$(id -u)" != 0 ]; then
  echo "slurm_batch_test: SKIP: needs root (installs slurm-wlm and munge, runs slurmd as root)"
  exit 77
fi

# Slurm and munge from Debian's archive (no daemon is started by the packages: no init system).
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  say "installing slurm-wlm and munge"
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null 2>&1 ||
    { apt-get update >/dev/null && apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null; } ||
    fail "cannot install slurm-wlm and munge"
fi

# Everything in one folder; munged wants its socket folder 0755.
work=$(mktemp -d /tmp/airtwin_slurm.XXXXXX)
chmod 0755 "$work"
mkdir -p "$work/munge" "$work/state" "$work/spool" "$work/logs"
chmod 0755 "$work/munge"
pids=()
cleanup() {
  local status=$?
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  # munged runs as a daemon of its own: stopped by its pid file, and waited for, since it writes
  # its seed file and removes its socket as it exits (a folder removed under it is not empty).
  if [ -f "$work/munge/munged.pid" ]; then
    local munged_pid
    munged_pid=$(cat "$work/munge/munged.pid")
    kill -TERM "$munged_pid" 2>/dev/null || true
    for _ in $(seq 100); do kill -0 "$munged_pid" 2>/dev/null || break; sleep 0.1; done
  fi
  if [ "$status" = 0 ]; then
    rm -rf "$work" || echo "slurm_batch_test: could not remove $work" >&2
  else
    echo "slurm_batch_test: logs kept in $work (slurmctld.log, slurmd.log, logs/)" >&2
  fi
}
trap cleanup EXIT

# The reference: the same batch unsharded on this machine.
say "unsharded batch on this machine"
"$airtwin" batch "${scenarios[@]}" --seeds "$seeds" --quiet --out "$work/local" >/dev/null

# munge: a fresh key; munged returns once its socket answers (it detaches only after initialising),
# so nothing polls for it.
mungekey --create --keyfile="$work/munge/munge.key" >/dev/null 2>&1 ||
  dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 0600 "$work/munge/munge.key"
munged --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket.2" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
  --seed-file="$work/munge/munged.seed" >"$work/logs/munged.out" 2>&1 ||
  fail "munged did not start: $(tail -3 "$work/logs/munged.out" "$work/munge/munged.log" 2>/dev/null)"

# slurm.conf: one node on loopback, no cgroups, no accounting; ports of our own.
host=$(hostname -s)
port=$((20000 + ($$ % 2000) * 2))
cat >"$work/slurm.conf" <<CONF
ClusterName=airtwintest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket.2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MailProg=/bin/true
ReturnToService=2
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=batch Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:4
CONF
export SLURM_CONF="$work/slurm.conf"

# The two daemons. Slurm says nothing when it is ready: its own client asks, within a deadline.
slurmctld -D -f "$SLURM_CONF" >"$work/logs/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/logs/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 300); do scontrol ping 2>/dev/null | grep -q "is UP" && break; sleep 0.1; done
scontrol ping 2>/dev/null | grep -q "is UP" || fail "slurmctld did not come up (see $work/slurmctld.log)"
for _ in $(seq 300); do [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && break; sleep 0.1; done
[ "$(sinfo -h -o %t)" = idle ] || fail "the node is not idle: $(sinfo -h -o %t) (see $work/slurmd.log)"
say "cluster up ($host, port $port)"

# The documented script as an array over the shards.
cd "$work"
submitted=$EPOCHREALTIME
# sbatch --wait returns when every task has ended (its status: the worst task's).
say "submitting the job array ($shards tasks)"
AIRTWIN="$airtwin" timeout 300 sbatch --wait --parsable --array=0-$((shards - 1)) \
  --cpus-per-task=1 --output="$work/logs/%A_%a.out" "$src/scripts/slurm/batch.sbatch" "$shards" \
  "$work/cluster" "${scenarios[@]}" --seeds "$seeds" >"$work/logs/sbatch.out" ||
  fail "the job array failed or ran past 300 s: $(tail -3 "$work/logs/sbatch.out")"
array_s=$(since "$submitted")
say "array done in $array_s s"
for ((i = 0; i < shards; i++)); do
  [ -f "$work/cluster/shard-$i/runs.csv" ] ||
    fail "shard $i wrote no runs.csv; its log: $(cat "$work"/logs/*_"$i".out 2>/dev/null | tail -5)"
done

# Merged, the shards are the unsharded batch.
"$airtwin" batch-merge "$work"/cluster/shard-* --quiet --out "$work/merged" >/dev/null
cmp "$work/local/runs.csv" "$work/merged/runs.csv" || fail "runs.csv differs from the unsharded batch"
for png in "$work"/local/plots/*.png; do
  cmp "$png" "$work/merged/plots/$(basename "$png")" || fail "$(basename "$png") differs"
done
results() { sed '/^## Timing/,$d' "$1"; }
[ "$(results "$work/local/report.md")" = "$(results "$work/merged/report.md")" ] ||
  fail "report.md differs from the unsharded batch (before its timing section)"
if command -v python3 >/dev/null; then
  python3 - "$work/local/report.json" "$work/merged/report.json" <<'PY' || fail "report.json differs"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for j in (a, b):
    j.pop("timing")
sys.exit(0 if a == b else 1)
PY
fi
rows=$(($(wc -l <"$work/merged/runs.csv") - 1))
say "PASS: $shards shards, $rows runs merged equal the unsharded batch (array $array_s s)"
