#!/usr/bin/env bash
# Simulink's ROS 2 time model, played by two test nodes (docs/simulink.md), against quadcosim's nodes
# in lockstep on the paper's altitude step (15 s: 1501 plant ticks at 0.01 s, 751 control steps at
# 0.02 s). The reference is the in-process run of the same scenario (`quadcosim run`): a peer that
# computes each control step on exactly that step's samples flies exactly its trajectory, so the
# state and command columns must be the same bytes (the controller columns are not compared: the
# test nodes publish no controller status).
#   usage: simulink_cases.sh QUADCOSIM SOURCE_DIR CASE DOMAIN CLOCK_STEPPED_CONTROLLER WAITING_PLANT
# Cases:
#   clock_stepped_controller  `quadcosim plant --clock-after-sensors` drives the /clock-stepped
#       controller: no timeout, every one of the 751 steps on samples stamped with its own /clock
#       time, the reference trajectory, and 5 runs with byte-identical trajectory CSVs.
#   clock_first_is_stale  the same without --clock-after-sensors (/clock before the samples): no step
#       sees its own tick's samples, each sees the previous tick's (the first ones, before the node
#       has discovered the plant's writers, none), so the flight differs from the reference.
#       Measures that DDS delivered /clock and the samples in publication order.
#   waiting_plant  `quadcosim controller` drives a plant that publishes /clock and the samples at
#       100 Hz and blocks each control step until a command arrives: every command answers its own
#       step (its label), the reference trajectory, 5 runs byte-identical.
set -euo pipefail
bin="$1"; src="$2"; ctl_bin="$5"; plant_bin="$6"
source "$src/tests/lib/process_case.sh" "$3" "$4"
scenario="$src/scenarios/paper/altitude_step.yaml"
runs=5

"$bin" run "$scenario" --out "$tmp/ref" --no-plots > "$tmp/ref.log" 2>&1 || fail "in-process reference run failed"

# same_flight CSV: the state and command columns (t .. cmd4) of CSV equal the reference's, as text.
same_flight() {
  cut -d, -f1-25 "$1" > "$tmp/a.cols"
  cut -d, -f1-25 "$tmp/ref/trajectory.csv" > "$tmp/b.cols"
  cmp -s "$tmp/a.cols" "$tmp/b.cols"
}

# drive_clock_stepped RUN [PLANT FLAGS...]: quadcosim plant in lockstep + the /clock-stepped node.
drive_clock_stepped() {
  local run="$1"; shift
  "$ctl_bin" "$scenario" "$tmp/steps_$run.csv" 2 > "$tmp/node_$run.json" 2> "$tmp/node_$run.log" &
  local node_pid=$!
  local rc=0
  "$bin" plant --scenario "$scenario" --timeout 20 --record "$tmp/plant_$run.csv" "$@" > "$tmp/plant_$run.log" 2>&1 || rc=$?
  wait "$node_pid" || fail "run $run: the /clock-stepped node exited $?"
  [ "$rc" -eq 0 ] || fail "run $run: the plant exited $rc"
}

case "$case_name" in
  clock_stepped_controller)
    for run in $(seq 1 $runs); do
      drive_clock_stepped "$run" --clock-after-sensors
      python3 - "$tmp/node_$run.json" "$tmp/steps_$run.csv" <<'PY' || fail "run $run: steps not on their own samples"
import json, sys
r = json.loads(open(sys.argv[1]).read())
rows = [list(map(int, l.split(","))) for l in open(sys.argv[2])]
bad = [row for row in rows if not row[0] == row[1] == row[2] == row[3]]
assert r["steps"] == 751 and len(rows) == 751, (r, len(rows))
assert r["stale_steps"] == 0 and not bad, (r, bad[:3])
assert [row[0] for row in rows] == [i * 20_000_000 for i in range(751)], "steps not at 0, 0.02, ..., 15 s"
assert r["non_hits"] >= 750, r  # the odd ticks' /clock (0.01, 0.03, ...): no step
print("run", sys.argv[1][-6], r)
PY
      grep -q "stale 0" "$tmp/plant_$run.log" || fail "run $run: the plant dropped commands as stale"
      same_flight "$tmp/plant_$run.csv" || fail "run $run: the flight differs from the in-process reference"
      [ "$run" -eq 1 ] || cmp "$tmp/plant_1.csv" "$tmp/plant_$run.csv" || fail "run $run: CSV differs from run 1"
    done
    grep "lockstep round trip" "$tmp/plant_1.log" || true
    echo "$runs runs: 751 steps each on their own tick's samples, byte-identical, equal to in-process"
    ;;
  clock_first_is_stale)
    drive_clock_stepped 1
    python3 - "$tmp/node_1.json" "$tmp/steps_1.csv" <<'PY' || fail "steps did not see the previous tick's samples"
import json, sys
r = json.loads(open(sys.argv[1]).read())
rows = [list(map(int, l.split(","))) for l in open(sys.argv[2])]
assert r["steps"] == 751 and len(rows) == 751, (r, len(rows))
assert r["stale_steps"] >= 750, r  # not one step after t = 0 on its own tick's samples
# Step 0 may see its own samples: while discovery settles the plant publishes tick 0 again after
# 50 ms, and the samples of the first round may be in when the second /clock comes. Until the node
# has discovered the plant's three writers a step lacks samples of some topic; from then on every
# step has those of 10 ms before.
blank = 1
while blank < len(rows) and -1 in rows[blank][1:]:
    blank += 1
prev = [row for row in rows[blank:] if row[1] == row[2] == row[3] == row[0] - 10_000_000]
assert blank <= 25 and len(prev) == 751 - blank, (blank, len(prev), [row for row in rows[blank:] if row not in prev][:6])
print(r, f"step 0 on {rows[0][1:]}, {blank - 1} more lacking samples, then {len(prev)} on the samples of 10 ms before")
PY
    if same_flight "$tmp/plant_1.csv"; then fail "stale samples flew the reference trajectory"; fi
    ;;
  waiting_plant)
    for run in $(seq 1 $runs); do
      "$bin" controller --scenario "$scenario" > "$tmp/controller_$run.log" 2>&1 &
      ctl_pid=$!
      pids+=("$ctl_pid")
      "$plant_bin" "$scenario" "$tmp/plant_$run.csv" 20 > "$tmp/plant_$run.json" 2> "$tmp/plant_$run.log" \
        || fail "run $run: the waiting plant exited $?"
      kill -TERM "$ctl_pid"; wait "$ctl_pid" || true
      python3 - "$tmp/plant_$run.json" <<'PY' || fail "run $run: commands did not answer their own steps"
import json, sys
r = json.loads(open(sys.argv[1]).read())
assert r == {"steps": 1501, "commands": 751, "mismatched": 0}, r
print(r)
PY
      same_flight "$tmp/plant_$run.csv" || fail "run $run: the flight differs from the in-process reference"
      [ "$run" -eq 1 ] || cmp "$tmp/plant_1.csv" "$tmp/plant_$run.csv" || fail "run $run: CSV differs from run 1"
    done
    echo "$runs runs: 751 commands each answering their own step, byte-identical, equal to in-process"
    ;;
  *) fail "unknown case $case_name" ;;
esac
