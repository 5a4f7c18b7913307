#!/usr/bin/env bash
# The Slurm path for real: a private single-node cluster (munged, slurmctld -D, slurmd -D) in a temp
# dir, the sweep submitted as a job array with scripts/slurm/submit.sh, the merge job after it, and
# its summary.json compared byte for byte with the unsharded sweep's. Every daemon started here is
# stopped by PID on exit. Exit 77 (SKIPPED) with the reason when the daemons cannot start.
#   usage: slurm_test.sh QUADCOSIM_BINARY SOURCE_DIR PORT_BASE
set -uo pipefail
QC=$(realpath "$1")
SRC=$(realpath "$2")
PORT=${3:-16917}
skip() { echo "SKIPPED: $*" >&2; exit 77; }
fail() { echo "FAIL [slurm]: $*" >&2; for f in "$TMP"/*.log; do echo "== $f"; tail -20 "$f"; done >&2; exit 1; }
for b in munged slurmctld slurmd sbatch sinfo squeue; do
  command -v $b > /dev/null || PATH=$PATH:/usr/sbin command -v $b > /dev/null || skip "$b not installed (apt-get install slurm-wlm munge)"
done
export PATH=$PATH:/usr/sbin
[ "$(id -u)" -eq 0 ] || skip "needs root (SlurmUser root, slurmd runs jobs as their user)"
TMP=$(mktemp -d /tmp/quadcosim-slurm.XXXXXX)
chmod 755 "$TMP"
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2> /dev/null; done
  for p in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2> /dev/null || break; sleep 0.1; done
    kill -9 "$p" 2> /dev/null
  done
  [ -f "$TMP/munged.pid" ] && kill "$(cat "$TMP/munged.pid")" 2> /dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT

# munge: a private key and socket.
mkdir -p "$TMP/munge"
chmod 700 "$TMP/munge"
dd if=/dev/urandom of="$TMP/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$TMP/munge/munge.key"
munged --socket="$TMP/munge/sock" --key-file="$TMP/munge/munge.key" --pid-file="$TMP/munged.pid" \
  --log-file="$TMP/munged.log" --seed-file="$TMP/munge/seed" --force > "$TMP/munged.start.log" 2>&1 \
  || skip "munged did not start: $(tail -1 "$TMP/munged.start.log")"
for _ in $(seq 50); do [ -S "$TMP/munge/sock" ] && break; sleep 0.1; done
[ -S "$TMP/munge/sock" ] || skip "munged made no socket"

HOST=$(hostname -s)
mkdir -p "$TMP/state" "$TMP/spool"
cat > "$TMP/slurm.conf" <<CONF
ClusterName=quadcosim
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$TMP/munge/sock
StateSaveLocation=$TMP/state
SlurmdSpoolDir=$TMP/spool
SlurmctldPidFile=$TMP/slurmctld.pid
SlurmdPidFile=$TMP/slurmd.pid
SlurmctldLogFile=$TMP/slurmctld.log
SlurmdLogFile=$TMP/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$TMP/slurm.conf
slurmctld -D -i -f "$SLURM_CONF" > "$TMP/slurmctld.out.log" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" -N "$HOST" > "$TMP/slurmd.out.log" 2>&1 &
PIDS+=($!)
idle=""
for _ in $(seq 60); do
  for p in "${PIDS[@]}"; do kill -0 "$p" 2> /dev/null || skip "a Slurm daemon exited at start: $(tail -n 2 "$TMP"/slurm*.log | tr '\n' ' ')"; done
  idle=$(sinfo -h -N -o '%t' 2> /dev/null | head -1)
  [ "$idle" = "idle" ] && break
  sleep 0.5
done
[ "$idle" = "idle" ] || skip "the node did not become idle in 30 s (state '$idle')"

OUT=$TMP/out
SCN=$(realpath "$SRC/scenarios/realism/hover_wind_gusts.yaml")
ARGS=(--runs 12 --seed 8 --vary mass=10% --vary controller.altitude.kd=uniform\(2,3.5\) --min-pass-rate 0)
"$QC" sweep "$SCN" "${ARGS[@]}" --no-plots --out "$TMP/unsharded" > "$TMP/unsharded.log" 2>&1 || fail "unsharded sweep"
# Submitted as docs/sweeps.md shows, with OUT and SCENARIO relative to the current folder (the jobs
# run in OUT): submit.sh makes them absolute, so the header and summary.json name $SCN.
merge=$(cd "$TMP" && QUADCOSIM=$QC bash "$SRC/scripts/slurm/submit.sh" out 3 "$(realpath --relative-to=. "$SCN")" \
        "${ARGS[@]}" 2> "$TMP/submit.log") || fail "submit: $(cat "$TMP/submit.log")"
for _ in $(seq 240); do
  [ -z "$(squeue -h -o %i 2> /dev/null)" ] && break
  sleep 0.5
done
[ -z "$(squeue -h -o %i)" ] || fail "jobs still queued after 120 s: $(squeue)"
ls "$OUT"/shard-1/shard.json "$OUT"/shard-2/shard.json "$OUT"/shard-3/shard.json > /dev/null || fail "a shard did not write shard.json"
[ -s "$OUT/merged/summary.json" ] || fail "merge job $merge wrote no summary.json: $(cat "$OUT/merge.out" 2> /dev/null)"
cmp "$OUT/merged/summary.json" "$TMP/unsharded/summary.json" || fail "summary.json from Slurm differs from the unsharded sweep's"
echo "slurm: 3 array tasks and the merge job $merge: summary.json identical to the unsharded sweep's"
