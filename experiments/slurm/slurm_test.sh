#!/usr/bin/env bash
# A real single-node Slurm test of `evio campaign --slurm` and `collect`.
#
# Brings up munged + slurmctld + slurmd for one node on localhost (Debian's
# slurm-wlm and munge, installed by scripts/install_deps.sh; this script
# installs nothing), with every configuration, key, socket, state and log
# file in a temporary folder. Then: writes the job-array script of a small
# campaign, submits it with sbatch, waits (bounded), runs `evio campaign
# collect --require-complete`, checks that every array task completed and
# that the summary equals the one of a local run of the same campaign, and
# shuts the daemons down again, by their pids, also when anything fails.
# Needs root (as CI runs); exits 77 (ctest: skipped) when not root or when
# Slurm is not installed.
#
# usage: slurm_test.sh <evio> <campaign.yaml> <work-folder> [--set key=value]...
#   e.g. slurm_test.sh build/bin/evio experiments/campaigns/smoke.yaml /tmp/slurm-test --set 'seeds=[1]'
# KEEP_SLURM_TMP=1 keeps the temporary Slurm folder for inspection.
set -euo pipefail

if [ $# -lt 3 ]; then
  sed -n '2,20p' "$0" >&2
  exit 2
fi
evio=$(readlink -f "$1")
campaign=$(readlink -f "$2")
work=$3
shift 3
overrides=("$@")
timeout_s=${SLURM_TEST_TIMEOUT_S:-240}

if [ "$(id -u)" -ne 0 ]; then
  echo "slurm_test: skipped: needs root (munged/slurmd run as root here)"
  exit 77
fi
for cmd in munged munge slurmctld slurmd sbatch squeue scontrol scancel; do
  if ! command -v "$cmd" > /dev/null; then
    echo "slurm_test: skipped: $cmd not found (scripts/install_deps.sh installs slurm-wlm and munge)"
    exit 77
  fi
done

tmp=$(mktemp -d /tmp/evio-slurm.XXXXXX)
chmod 755 "$tmp"  # munged wants every directory on its socket path searchable by all
jobid=""

log() { echo "slurm_test: $*"; }

cleanup() {
  local rc=$?
  set +e
  if [ -n "$jobid" ] && [ -f "$tmp/slurm.conf" ]; then
    SLURM_CONF="$tmp/slurm.conf" scancel "$jobid" 2> /dev/null
  fi
  # Stop the daemons we started, by pid, in reverse order.
  for d in slurmd slurmctld munged; do
    if [ -f "$tmp/$d.pid" ]; then
      pid=$(cat "$tmp/$d.pid")
      if kill -0 "$pid" 2> /dev/null; then
        kill "$pid" 2> /dev/null
        for _ in $(seq 1 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
        kill -0 "$pid" 2> /dev/null && kill -9 "$pid" 2> /dev/null
      fi
    fi
  done
  if [ $rc -ne 0 ]; then
    log "FAILED (exit $rc); logs follow"
    for f in "$tmp"/slurmctld.log "$tmp"/slurmd.log "$work"/results/slurm/*.out; do
      [ -f "$f" ] && { echo "----- $f (tail)"; tail -n 25 "$f"; }
    done
  fi
  if [ "${KEEP_SLURM_TMP:-0}" = 1 ]; then log "kept $tmp"; else rm -rf "$tmp"; fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# --- munge ----------------------------------------------------------------
mkdir -p "$tmp/munge"
chmod 755 "$tmp/munge"
dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge.key"
munged --key-file="$tmp/munge.key" --socket="$tmp/munge/munge.socket" --pid-file="$tmp/munged.pid" \
  --log-file="$tmp/munged.log" --seed-file="$tmp/munged.seed"
echo probe | munge -S "$tmp/munge/munge.socket" | unmunge -S "$tmp/munge/munge.socket" > /dev/null
log "munged up (pid $(cat "$tmp/munged.pid"))"

# --- slurm ----------------------------------------------------------------
host=$(hostname -s)
port=$((20000 + RANDOM % 20000))
mem_mb=$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" << CONF
# single-node test cluster written by experiments/slurm/slurm_test.sh
ClusterName=eviotest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
PlugStackConfig=/dev/null
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$mem_mb State=UNKNOWN
PartitionName=evio Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 100); do
  state=$(sinfo -h -n "$host" -o %t 2> /dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.2
done
[ "$state" = idle ] || { log "node did not come up (state '$state')"; exit 1; }
log "slurmctld (pid $(cat "$tmp/slurmctld.pid")) and slurmd (pid $(cat "$tmp/slurmd.pid")) up on port $port"

# --- the campaign as a job array -------------------------------------------
rm -rf "$work"
mkdir -p "$work"
results="$work/results"
set_args=()
for o in "${overrides[@]}"; do set_args+=("$o"); done
"$evio" campaign "$campaign" -o "$results" --slurm "$work/array.sh" "${set_args[@]}"
jobid=$(sbatch --parsable "$work/array.sh")
jobid=${jobid%%;*}
tasks=$(grep -c . "$results/slurm/tasks.txt")
log "submitted array job $jobid ($tasks tasks)"

start=$SECONDS
while [ -n "$(squeue -h -j "$jobid" 2> /dev/null)" ]; do
  if [ $((SECONDS - start)) -gt "$timeout_s" ]; then
    log "array job $jobid still running after $timeout_s s"
    exit 1
  fi
  sleep 1
done
log "array job finished in $((SECONDS - start)) s"
states=$(scontrol show job -o "$jobid" | grep -o 'JobState=[A-Z_]*' | sort | uniq -c)
echo "$states"
completed=$(scontrol show job -o "$jobid" | grep -c 'JobState=COMPLETED' || true)
[ "$completed" -eq "$tasks" ] || { log "only $completed of $tasks array tasks completed"; exit 1; }

"$evio" campaign collect "$campaign" -o "$results" --require-complete "${set_args[@]}"

# --- the same campaign run locally must give the same summary ----------------
"$evio" campaign "$campaign" -o "$work/local" -j 2 -q "${set_args[@]}"
if ! cmp "$results/summary.csv" "$work/local/summary.csv"; then
  log "summary.csv from Slurm differs from the local run"
  diff "$results/summary.csv" "$work/local/summary.csv" | head -20
  exit 1
fi
jobs=$(($(wc -l < "$results/summary.csv") - 1))
log "PASSED: $jobs jobs in $tasks array tasks; summary.csv identical to a local run"
