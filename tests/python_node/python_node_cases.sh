#!/usr/bin/env bash
# Controllers written in Python (tests/python_node/altitude_pd.py) in the CLI: in process (`run`,
# `sweep`) and as the DDS controller node (`controller --python`, a scenario's `controller: {python:
# ...}`). Usage: python_node_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID. Every case needs a CLI built
# with Python and exits 77 (skipped) on one built without.
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
here="$src/tests/python_node"
paper="$src/scenarios/paper"

# The paper's altitude step (z_des 0 -> 10 m at t = 0) without its paper criteria, flying the class
# $1 of altitude_pd.py with the controller keys $2 (", key: value, ..."), $3 s long, written to $4
# next to a copy of altitude_pd.py (found in the scenario's folder).
scenario() {
  sed -e '/^analysis:/,$d' -e "s/^  duration_s: .*/  duration_s: $3/" \
      -e "s/^controller:\$/controller:\n  python: \"altitude_pd:$1\"$2/" "$paper/altitude_step.yaml" \
    | sed -e "s/^  python: \"altitude_pd:$1\", /  python: \"altitude_pd:$1\"\n  /" > "$4"
  grep -q "python: \"altitude_pd:$1\"" "$4" || fail "could not write $4"
  cp "$here/altitude_pd.py" "$(dirname "$4")/"
}

# z of the last row of trajectory CSV $1 is within $2 m of 10 m.
reaches() {
  local z; z="$(tail -1 "$1" | cut -d, -f4)"
  awk -v z="$z" -v tol="$2" 'BEGIN { exit !(z > 10 - tol && z < 10 + tol) }' || fail "$1: z at the end is $z, not 10 +- $2 m"
  echo "$1: z at the end $z m"
}

# Sends SIGTERM to pid $1 and waits up to $2 s for it to end; its exit status in $rc.
term_within() {
  local t0 t1; t0="$(date +%s.%N)"
  kill -TERM "$1"
  for _ in $(seq 1 $(( $2 * 20 ))); do kill -0 "$1" 2>/dev/null || break; sleep 0.05; done
  kill -0 "$1" 2>/dev/null && fail "still running $2 s after SIGTERM"
  t1="$(date +%s.%N)"
  set +e; wait "$1"; rc=$?; set -e
  echo "ended $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }') s after SIGTERM (exit $rc)"
}

case "$case_name" in
  lockstep_matches_run)  # the same Python controller in process and as a DDS lockstep node: same bytes
    skip_without_python "$bin"
    scenario AltitudePD "" 10 "$tmp/pd.yaml"
    "$bin" run "$tmp/pd.yaml" --out "$tmp/run" --no-plots > "$tmp/run.log" 2>&1 || fail "run failed"
    reaches "$tmp/run/trajectory.csv" 0.05
    # The node flies --python (found in the current directory) over the scenario's setpoints.
    (cd "$here" && exec "$bin" controller --scenario "$tmp/pd.yaml" --python altitude_pd:AltitudePD) \
      > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    t0="$(date +%s.%N)"
    "$bin" plant --scenario "$tmp/pd.yaml" --record "$tmp/plant.csv" > "$tmp/plant.log" 2>&1 || fail "plant failed"
    t1="$(date +%s.%N)"
    grep -q "controller python altitude_pd:AltitudePD" "$tmp/controller.log" || fail "the node did not say it flies Python"
    cmp "$tmp/run/trajectory.csv" "$tmp/plant.csv" || fail "the DDS lockstep trajectory differs from the in-process run"
    rows="$(($(wc -l < "$tmp/plant.csv") - 1))"
    [ "$rows" -gt 900 ] || fail "trajectory too short ($rows rows)"
    echo "lockstep over DDS: trajectory.csv byte-identical to quadcosim run ($rows rows, $(awk -v a="$t0" -v b="$t1" \
      'BEGIN { printf "%.2f s wall for 10 s simulated: %.1fx real time", b - a, 10 / (b - a) }'))"
    term_within "$cpid" 2
    ;;

  param_set)  # a declared Python parameter changed with `quadcosim param set` mid-run takes effect
    skip_without_python "$bin"
    # kp_z 0: thrust m g only, the vehicle stays on the ground; kp_z 4 from about 3 s on: it climbs.
    scenario AltitudePD ", kp_z: 0" 6 "$tmp/pd.yaml"
    "$bin" controller --scenario "$tmp/pd.yaml" --realtime > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    "$bin" param get /attitude_controller kp_z > "$tmp/get0.log" 2>&1 || fail "param get (before) failed"
    grep -qx "Double value is: 0.0" "$tmp/get0.log" || fail "kp_z does not start at 0: $(cat "$tmp/get0.log")"
    "$bin" plant --scenario "$tmp/pd.yaml" --realtime --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1 &
    ppid=$!; pids+=("$ppid")
    sleep 3  # the plant's simulated clock is well past 1 s by then, also on a loaded machine
    "$bin" param set /attitude_controller kp_z 4.0 > "$tmp/set.log" 2>&1 || fail "param set failed"
    grep -qx "Set parameter successful" "$tmp/set.log" || fail "param set: unexpected output"
    "$bin" param get /attitude_controller kp_z > "$tmp/get.log" 2>&1 || fail "param get failed"
    grep -qx "Double value is: 4.0" "$tmp/get.log" || fail "param get: expected 4.0, got $(cat "$tmp/get.log")"
    set +e; "$bin" param set /attitude_controller kp_z 1000 > "$tmp/refused.log" 2>&1; rc=$?; set -e
    [ "$rc" -eq 1 ] || fail "out-of-range kp_z: expected exit 1, got $rc"
    timeout 60 tail --pid="$ppid" -f /dev/null || fail "plant did not finish"
    wait "$ppid" || fail "plant failed"
    # Before the change (t < 1 s) on the ground; at the end well above it.
    z_early="$(awk -F, 'NR > 1 && $1 <= 1.0 { z = $4 } END { print z }' "$tmp/t.csv")"
    z_end="$(tail -1 "$tmp/t.csv" | cut -d, -f4)"
    awk -v z="$z_early" 'BEGIN { exit !(z < 0.01) }' || fail "climbed before the change (z at 1 s = $z_early)"
    awk -v z="$z_end" 'BEGIN { exit !(z > 2.0) }' || fail "did not climb after kp_z 4: z at the end = $z_end"
    echo "kp_z 0 -> 4 by param set: z at 1 s $z_early m, at the end $z_end m"
    ;;

  raising_stops)  # a controller that raises ends the node with exit 5 and a message naming it
    skip_without_python "$bin"
    scenario Raising "" 10 "$tmp/raise.yaml"
    "$bin" controller --scenario "$tmp/raise.yaml" > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    set +e
    "$bin" plant --scenario "$tmp/raise.yaml" --timeout 2 > "$tmp/plant.log" 2>&1
    timeout 20 tail --pid="$cpid" -f /dev/null
    wait "$cpid"; rc=$?
    set -e
    [ "$rc" -eq 5 ] || fail "the node exited $rc, expected 5"
    grep -q "error: controller: .*Raising.*step 12 (t = 0.24" "$tmp/controller.log" \
      || fail "no message naming the class, step 12 and its time"
    grep -q "the test asks step 12 to fail" "$tmp/controller.log" || fail "the Python exception's text is missing"
    grep "error: controller:" "$tmp/controller.log"
    ;;

  raising_safety)  # --on-controller-error safety: the failed steps get the safety command, counted
    skip_without_python "$bin"
    scenario Raising ", bad_count: 3" 10 "$tmp/raise.yaml"
    "$bin" controller --scenario "$tmp/raise.yaml" --on-controller-error safety > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    "$bin" plant --scenario "$tmp/raise.yaml" --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1 || fail "plant failed"
    term_within "$cpid" 2
    [ "$rc" -eq 0 ] || fail "the node exited $rc after SIGTERM, expected 0"
    grep -q "controller: 3 failed steps (safety command sent instead)" "$tmp/controller.log" \
      || fail "the node did not count 3 failed steps"
    [ "$(grep -c "the safety command was sent instead" "$tmp/controller.log")" -eq 1 ] \
      || fail "expected one log line (the 1st failure; then every 100th)"
    col="$(head -1 "$tmp/t.csv" | tr ',' '\n' | grep -nx safety | cut -d: -f1)"
    safety_rows="$(awk -F, -v c="$col" 'NR > 1 && $c == 1' "$tmp/t.csv" | wc -l)"
    # 3 control periods of 2 plant ticks each carry the safety command.
    [ "$safety_rows" -eq 6 ] || fail "expected 6 plant rows under the safety command, got $safety_rows"
    reaches "$tmp/t.csv" 0.1
    echo "3 failed steps flown on the safety command ($safety_rows plant rows)"
    ;;

  blocking_realtime)  # a controller that sleeps 10 s: the node serves parameters, sends safety, ends on SIGTERM
    skip_without_python "$bin"
    scenario Blocking "" 30 "$tmp/block.yaml"
    "$bin" controller --scenario "$tmp/block.yaml" --realtime > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    "$bin" plant --scenario "$tmp/block.yaml" --realtime > "$tmp/plant.log" 2>&1 &
    pids+=($!)
    sleep 1.5  # step 5 (0.1 s after the first sample) is asleep by now
    t0="$(date +%s.%N)"
    "$bin" param get /attitude_controller kp_z --timeout 2 > "$tmp/get.log" 2>&1 || fail "param get failed while blocked"
    t1="$(date +%s.%N)"
    grep -qx "Double value is: 4.0" "$tmp/get.log" || fail "param get: $(cat "$tmp/get.log")"
    echo "param get answered in $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }') s with the step asleep"
    grep -q "the controller did not return within 0.015 s; the safety command was sent" "$tmp/controller.log" \
      || fail "no late-period message"
    term_within "$cpid" 2
    [ "$rc" -eq 0 ] || fail "exit $rc after SIGTERM, expected 0"
    grep -E "late periods" "$tmp/controller.log" || fail "no late-period count"
    ;;

  blocking_lockstep)  # the same in lockstep: the plant's timeout policy applies; the node serves and stops
    skip_without_python "$bin"
    scenario Blocking "" 10 "$tmp/block.yaml"
    "$bin" controller --scenario "$tmp/block.yaml" > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    set +e
    "$bin" plant --scenario "$tmp/block.yaml" --timeout 1 > "$tmp/plant.log" 2>&1 &
    ppid=$!; pids+=("$ppid")
    set -e
    sleep 0.5
    "$bin" param get /attitude_controller kp_z --timeout 2 > "$tmp/get.log" 2>&1 || fail "param get failed while blocked"
    grep -qx "Double value is: 4.0" "$tmp/get.log" || fail "param get: $(cat "$tmp/get.log")"
    set +e; wait "$ppid"; prc=$?; set -e
    [ "$prc" -eq 4 ] || fail "the plant exited $prc, expected 4 (lockstep timeout, --on-timeout abort)"
    grep -qE "lockstep timeout: no motor command on /drone/motor_commands for tick 1[01] " "$tmp/plant.log" \
      || fail "the plant did not time out on tick 10 (step 5's answer)"
    "$bin" param get /attitude_controller kp_z --timeout 2 > "$tmp/get2.log" 2>&1 || fail "param get failed after the plant"
    term_within "$cpid" 2
    [ "$rc" -eq 0 ] || fail "exit $rc after SIGTERM, expected 0"
    ;;

  run_and_sweep)  # `run` and `sweep` of a scenario with controller: {python: ...}; sweep runs = single runs
    skip_without_python "$bin"
    scenario AltitudePD "" 6 "$tmp/pd.yaml"
    # Something for the sweep to judge: the step's overshoot, loosely.
    printf 'analysis:\n  steps:\n    - channel: z\n      at_s: 0\n      criteria:\n        overshoot_pct: [null, 50]\n' >> "$tmp/pd.yaml"
    export PYTHONPATH="$here"  # the sweep's copy of the scenario is in --out, without the module
    "$bin" sweep "$tmp/pd.yaml" --runs 3 --jobs 2 --seed 7 --vary mass=10% --keep all --min-pass-rate 0 \
      --out "$tmp/sweep" > "$tmp/sweep.log" 2>&1 || fail "sweep failed"
    for r in 0 1 2; do
      "$bin" sweep rerun "$tmp/sweep" "$r" --out "$tmp/single$r" --no-plots > "$tmp/rerun$r.log" 2>&1 \
        || fail "sweep rerun $r failed"
      cmp "$tmp/sweep/runs/000$r/trajectory.csv" "$tmp/single$r/trajectory.csv" \
        || fail "sweep run $r differs from the same run flown alone"
    done
    if cmp -s "$tmp/sweep/runs/0000/trajectory.csv" "$tmp/sweep/runs/0001/trajectory.csv"; then
      fail "the drawn masses changed nothing"
    fi
    echo "3-run mass sweep (--jobs 2): every run byte-identical to the run flown alone"
    ;;

  *) fail "unknown case" ;;
esac
echo "ok [$case_name]"
