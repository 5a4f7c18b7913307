#!/usr/bin/env bash
# Ctrl-C (SIGINT) during a long in-process run: exit 130, the CSV holds what ran and run.mcap is a
# finished file (it ends with the MCAP magic, after the summary and footer). The same for an in-process
# swarm: exit 130 after the block being flown, each recorded vehicle's CSV in whole rows, no summary.
set -euo pipefail
bin="$1"; src="$2"
tmp="$(mktemp -d)"
pid=""
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT

# interrupt LOG WAIT_FOR_FILE COMMAND...: starts the command, sends SIGINT a second after WAIT_FOR_FILE
# has content, and sets rc to its exit status.
interrupt() {
  local log="$1" file="$2"
  shift 2
  "$@" > "$log" 2>&1 &
  pid=$!
  for _ in $(seq 100); do [ -s "$file" ] && break; sleep 0.05; done
  sleep 1
  kill -INT "$pid"
  set +e
  wait "$pid"; rc=$?
  set -e
  pid=""
  [ "$rc" -eq 130 ] || { cat "$log"; echo "FAIL: expected exit 130, got $rc"; exit 1; }
  grep -q "interrupted" "$log" || { echo "FAIL: no message about the interruption in $log"; exit 1; }
}

sed 's/duration_s: 15/duration_s: 100000/' "$src/scenarios/paper/altitude_step.yaml" > "$tmp/long.yaml"
interrupt "$tmp/log" "$tmp/run/run.mcap" "$bin" run "$tmp/long.yaml" --out "$tmp/run" --no-plots
rows=$(($(wc -l < "$tmp/run/trajectory.csv") - 1))
[ "$rows" -gt 1000 ] || { echo "FAIL: only $rows rows recorded"; exit 1; }
[ "$(tail -c 8 "$tmp/run/run.mcap" | od -An -tx1 | tr -d ' \n')" = "894d434150300d0a" ] \
  || { echo "FAIL: run.mcap does not end with the MCAP magic"; exit 1; }
echo "ok: interrupted after $rows ticks; files finished"

sed 's/duration_s: 20/duration_s: 100000/' "$src/scenarios/swarm/grid_takeoff.yaml" > "$tmp/swarm.yaml"
interrupt "$tmp/swarm.log" "$tmp/swarm/uav0000/trajectory.csv" \
  "$bin" run "$tmp/swarm.yaml" --vehicles 4 --out "$tmp/swarm" --no-plots
rows=$(($(wc -l < "$tmp/swarm/uav0000/trajectory.csv") - 1))
[ "$rows" -gt 1000 ] || { echo "FAIL: swarm: only $rows rows recorded"; exit 1; }
awk -F, 'NR == 1 {n = NF} NF != n {exit 1}' "$tmp/swarm/uav0000/trajectory.csv" ||
  { echo "FAIL: swarm: a partial row"; exit 1; }
[ ! -e "$tmp/swarm/summary.json" ] || { echo "FAIL: swarm: a summary of a run that did not end"; exit 1; }
echo "ok: swarm interrupted after $rows ticks of its recorded vehicle; files finished"
