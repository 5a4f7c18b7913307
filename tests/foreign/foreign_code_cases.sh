#!/usr/bin/env bash
# Foreign code that crashes, exits or hangs inside a run (docs/reliability.md, "Foreign code").
# Usage: foreign_code_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FAULTY_FMU_DIR
# The FMUs (faulty_fmu/faulty_fmu.c) misbehave at the doStep whose time reaches $FAULTY_FMU_AT as
# $FAULTY_FMU_FAULT says (segv, abort, exit, hang, error). Every process a case starts is ended by PID.
bin="$1"; src="$2"; fmus="$5"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
hover="$src/tests/faults/hover.yaml"
export TMPDIR="$tmp/tmpdir"  # where the master unpacks FMUs: it must be empty after every run
mkdir -p "$TMPDIR"

# A scenario of $1 simulated seconds: the hover, with `$2` (a YAML line) added.
scenario() {
  { sed "s/duration_s: 30/duration_s: $1/" "$hover"; echo "$2"; } > "$tmp/s.yaml"
  cp "$fmus"/faulty_plant.fmu "$fmus"/faulty_controller.fmu "$tmp/"
}
plant_fmu() { scenario "${1:-5}" "plant: {fmu: faulty_plant.fmu${2:-}}"; }

# A scenario of $1 simulated seconds flying tests/foreign/faulty_controller.py, with `$2` (YAML lines of
# its controller: section) added. SKIPPED where quadcosim was built without Python.
python_scenario() {
  { sed "s/duration_s: 30/duration_s: $1/" "$hover" | grep -v '^controller:\|z_des'
    printf 'controller:\n  python: "faulty_controller:Faulty"\n'; [ -z "${2:-}" ] || echo "$2"; } > "$tmp/s.yaml"
  cp "$src/tests/foreign/faulty_controller.py" "$tmp/"
}

# What every end must leave: no unpacked FMU, a CSV of whole rows up to the tick $1 whose step
# failed (its state at that time was complete), and a finished run.mcap (it ends with the MCAP magic).
check_outputs() {
  local at="$1" last
  [ -z "$(ls -A "$TMPDIR")" ] || fail "left in the temporary directory: $(ls -A "$TMPDIR")"
  last="$(tail -1 "$tmp/out/trajectory.csv" | cut -d, -f1)"
  python3 -c "import sys; t=float('$last'); sys.exit(0 if abs(t - $at) < 1e-9 else 1)" \
    || fail "trajectory.csv ends at t = $last, expected $at"
  [ "$(tail -c 8 "$tmp/out/run.mcap" | od -An -tx1 | tr -d ' \n')" = "894d434150300d0a" ] \
    || fail "run.mcap is not finished (no closing magic)"
  grep -q "trajectory.csv" "$tmp/out/.quadcosim-outputs.json" || fail "the manifest does not list trajectory.csv"
}

# run the scenario, expecting exit $1 and stderr lines matching each further argument
run_expect() {
  local want="$1"; shift
  local rc=0
  "$bin" run "$tmp/s.yaml" --out "$tmp/out" --no-plots ${RUN_FLAGS:-} > "$tmp/run.log" 2>&1 || rc=$?
  if [ "$rc" != "$want" ] && grep -q "built without Python" "$tmp/run.log"; then
    echo "SKIPPED: this quadcosim was built without Python"; exit 77
  fi
  [ "$rc" = "$want" ] || fail "run exited $rc, expected $want"
  for pattern in "$@"; do grep -qE "$pattern" "$tmp/run.log" || fail "no line matching '$pattern' in the run's output"; done
  echo "exit $rc: $(grep -m1 'error' "$tmp/run.log" | cut -c1-400)"
}

# Start the run in the background, wait until it hangs at $1 s (the CSV stops growing), send $2,
# and expect exit 130 within 2.5 s, with everything up to the hang recorded.
hang_and_signal() {
  local at="$1" sig="$2"
  FAULTY_FMU_FAULT=hang FAULTY_FMU_AT="$at" "$bin" run "$tmp/s.yaml" --out "$tmp/out" --no-plots ${RUN_FLAGS:-} \
    > "$tmp/run.log" 2>&1 &
  local pid=$!; pids+=("$pid")
  sleep 3  # the run reaches the hang within a few hundred milliseconds
  kill -0 "$pid" 2>/dev/null || fail "the run ended before the signal"
  local children; children="$(ps -o pid= --ppid "$pid" | tr -d ' ' | tr '\n' ' ')"
  [ -n "$children" ] || fail "the run has no FMU process"
  local t0; t0="$(date +%s.%N)"
  kill "-$sig" "$pid"
  local rc=0; wait "$pid" || rc=$?
  local took; took="$(python3 -c "print(round($(date +%s.%N) - $t0, 2))")"
  [ "$rc" = 130 ] || fail "run exited $rc after SIG$sig, expected 130"
  python3 -c "import sys; sys.exit(0 if $took <= 2.5 else 1)" || fail "the run took $took s to end after SIG$sig"
  for c in $children; do kill -0 "$c" 2>/dev/null && fail "the FMU's process $c outlived the run"; done
  grep -qE "interrupted" "$tmp/run.log" || fail "the run did not say it was interrupted"
  echo "SIG$sig during a hung doStep at t = $at s: exit 130 after $took s; children ($children) gone"
}

case "$case_name" in
  fmu_plant_segv)  # the plant FMU writes through a null pointer at t = 2 s
    plant_fmu
    FAULTY_FMU_FAULT=segv FAULTY_FMU_AT=2 run_expect 6 "faulty_plant" "tick 200 \(t = 2 s\)" "fmi2DoStep\(t = 2" \
      "killed by signal 11"
    check_outputs 2 ;;
  fmu_plant_abort)
    plant_fmu
    FAULTY_FMU_FAULT=abort FAULTY_FMU_AT=1.5 run_expect 6 "faulty_plant" "tick 150 \(t = 1.5 s\)" "killed by signal 6"
    check_outputs 1.5 ;;
  fmu_plant_exit)  # exit(0) inside doStep: not a success
    plant_fmu
    FAULTY_FMU_FAULT=exit FAULTY_FMU_AT=3 run_expect 6 "faulty_plant" "tick 300 \(t = 3 s\)" "exited with status 0"
    check_outputs 3 ;;
  fmu_plant_error)  # fmi2Error from doStep, isolated: the same message as in-process
    plant_fmu
    FAULTY_FMU_FAULT=error FAULTY_FMU_AT=1 run_expect 6 "faulty_plant" "tick 100 \(t = 1 s\)" "answered Error"
    check_outputs 1 ;;
  fmu_controller_segv)  # the controller FMU crashes at its control step at t = 2 s: exit 5
    scenario 5 ""
    sed -i 's/^controller:$/controller:\n  fmu: faulty_controller.fmu/' "$tmp/s.yaml"
    FAULTY_FMU_FAULT=segv FAULTY_FMU_AT=2 run_expect 5 "faulty_controller" "control step [0-9]+ \(t = 2 s\)" \
      "killed by signal 11"
    [ -z "$(ls -A "$TMPDIR")" ] || fail "left in the temporary directory: $(ls -A "$TMPDIR")" ;;
  fmu_hang_sigint)
    plant_fmu 30
    hang_and_signal 1 INT
    check_outputs 1 ;;
  fmu_hang_sigterm)
    plant_fmu 30
    hang_and_signal 2 TERM
    check_outputs 2 ;;
  fmu_hang_timeout)  # no signal: the plant FMU hangs in doStep at t = 1 s, its step_timeout_s ends it
    plant_fmu 30 ", step_timeout_s: 0.5"
    t0="$(date +%s.%N)"
    FAULTY_FMU_FAULT=hang FAULTY_FMU_AT=1 run_expect 6 "faulty_plant" "tick 100 \(t = 1 s\)" "fmi2DoStep\(t = 1" \
      "did not return within step_timeout_s = 0.5 s"
    took="$(python3 -c "print(round($(date +%s.%N) - $t0, 2))")"
    python3 -c "import sys; sys.exit(0 if $took < 10 else 1)" || fail "the run took $took s, the limit is 0.5 s"
    check_outputs 1
    [ -z "$(pgrep -P $$ -f faulty || true)" ] || fail "an FMU process outlived the run"
    # The limit is refused where it cannot be kept: a call in quadcosim's own process cannot be stopped.
    plant_fmu 30 ", step_timeout_s: 0.5, in_process: true"
    run_expect 2 "step_timeout_s: applies to an FMU in its own process" ;;
  fmu_controller_hang_timeout)  # the controller FMU hangs at its step at t = 2 s: exit 5 after 0.3 s
    scenario 5 ""
    sed -i 's/^controller:$/controller:\n  fmu: faulty_controller.fmu\n  step_timeout_s: 0.3/' "$tmp/s.yaml"
    FAULTY_FMU_FAULT=hang FAULTY_FMU_AT=2 run_expect 5 "faulty_controller" "control step [0-9]+ \(t = 2 s\)" \
      "did not return within step_timeout_s = 0.3 s"
    [ -z "$(ls -A "$TMPDIR")" ] || fail "left in the temporary directory: $(ls -A "$TMPDIR")" ;;
  fmu_dds_segv)  # over DDS the plant process survives its FMU's crash and exits 6; run passes 6 on
    plant_fmu
    RUN_FLAGS="--transport dds" FAULTY_FMU_FAULT=segv FAULTY_FMU_AT=2 run_expect 6 "faulty_plant" \
      "tick 200 \(t = 2 s\)" "killed by signal 11" "run: the plant exited with status 6"
    check_outputs 2 ;;
  isolation_bit_identical)  # the same bytes with the FMU in its own process and in quadcosim's
    plant_fmu 10
    run_expect 0
    mv "$tmp/out" "$tmp/isolated"
    plant_fmu 10 ", in_process: true"
    run_expect 0
    cmp "$tmp/isolated/trajectory.csv" "$tmp/out/trajectory.csv" || fail "trajectory.csv differs with in_process: true"
    echo "trajectory.csv identical ($(wc -l < "$tmp/out/trajectory.csv") lines) isolated and in-process" ;;
  dds_children_die_with_run)  # SIGKILL of run: its plant and controller die with it
    "$bin" run "$hover" --out "$tmp/out" --no-plots --transport dds --realtime > "$tmp/run.log" 2>&1 &
    pid=$!; pids+=("$pid")
    for _ in $(seq 1 100); do
      sleep 0.1
      children="$(ps -o pid= --ppid "$pid" | tr -d ' ' | tr '\n' ' ')"
      [ "$(echo $children | wc -w)" = 2 ] && break
    done
    [ "$(echo $children | wc -w)" = 2 ] || fail "expected a plant and a controller process, found '$children'"
    pids+=($children)
    sleep 1
    kill -KILL "$pid"
    wait "$pid" 2>/dev/null || true
    sleep 0.5
    # Gone, or a zombie that nobody reaped yet (PID 1 of a container may not): not running either way.
    for c in $children; do
      st="$(ps -o stat= -p "$c" 2>/dev/null || true)"
      [ -z "$st" ] || [[ "$st" == Z* ]] || fail "child $c outlived the SIGKILLed run (state $st)"
    done
    echo "children $children ended with the run" ;;
  dds_child_exit_code)  # the plant cannot write trajectory.csv (file size limit): run exits 3, as the plant
    trap '' XFSZ  # inherited: a write past the limit fails with EFBIG instead of killing the writer
    ( ulimit -f 64; exec "$bin" run "$hover" --out "$tmp/out" --no-plots --transport dds ) > "$tmp/run.log" 2>&1 \
      && rc=0 || rc=$?
    [ "$rc" = 3 ] || fail "run exited $rc, expected the plant's 3"
    grep -q "run: the plant exited with status 3" "$tmp/run.log" || fail "run did not name the plant's status"
    echo "run exited 3, the plant's code" ;;
  python_hang_sigint)  # a Python controller sleeping in step: Ctrl-C still ends the run, 130
    mkdir -p "$tmp/py"
    cat > "$tmp/py/sleepy.py" <<'PY'
import time
import quadcosim
class Sleepy(quadcosim.Controller):
    def step(self, obs, ref, dt):
        time.sleep(1000)
        return [0.0, 0.0, 0.0, 0.0]
PY
    { sed "s/duration_s: 30/duration_s: 5/" "$hover" | grep -v '^controller:\|z_des'; \
      printf 'controller:\n  python: "sleepy:Sleepy"\n'; } > "$tmp/py/s.yaml"  # no step_timeout_s: only a signal ends it
    "$bin" run "$tmp/py/s.yaml" --out "$tmp/out" --no-plots > "$tmp/run.log" 2>&1 &
    pid=$!; pids+=("$pid")
    sleep 3
    if ! kill -0 "$pid" 2>/dev/null; then
      grep -q "built without Python" "$tmp/run.log" && { echo "SKIPPED: this quadcosim was built without Python"; exit 77; }
      fail "the run ended before the signal"
    fi
    t0="$(date +%s.%N)"; kill -INT "$pid"; rc=0; wait "$pid" || rc=$?
    took="$(python3 -c "print(round($(date +%s.%N) - $t0, 2))")"
    [ "$rc" = 130 ] || fail "run exited $rc after SIGINT, expected 130"
    python3 -c "import sys; sys.exit(0 if $took <= 2.5 else 1)" || fail "took $took s to end after SIGINT"
    echo "SIGINT during a sleeping Python step: exit 130 after $took s" ;;
  python_segv | python_abort | python_exit | python_hang)  # each ends the run: exit 5, named, outputs kept
    python_scenario 5 "  step_timeout_s: 0.5"
    fault="${case_name#python_}"
    declare -A how=([segv]="killed by signal 11" [abort]="killed by signal 6" [exit]="exited with status 0"
                    [hang]="did not return within step_timeout_s = 0.5 s")
    FAULTY_FAULT="$fault" FAULTY_AT=2 run_expect 5 "faulty_controller.Faulty.step at step 100 \(t = 2 s\)" \
      "${how[$fault]}" "faulty controller: $fault at t = 2 s"
    check_outputs 1.99 ;;  # every tick before the control step that failed
  python_raise_one_exit_code)  # a raising step: exit 5 isolated, in quadcosim's process, over DDS and in a sweep
    python_scenario 5
    for how in isolated in_process dds; do
      flags=""; [ "$how" = dds ] && flags="--transport dds"
      in_process=0; [ "$how" = in_process ] && in_process=1
      rm -rf "$tmp/out"
      QUADCOSIM_PYTHON_IN_PROCESS=$in_process FAULTY_FAULT=raise FAULTY_AT=2 RUN_FLAGS="$flags" \
        run_expect 5 "faulty_controller.Faulty.step at step 100 \(t = 2 s\): raised ValueError"
    done
    # A sweep whose runs' controller raises exits 5 too, each run's error and its cause in summary.json.
    sed 's/^  duration_s: 15$/  duration_s: 3/; s/^controller:$/controller:\n  python: "faulty_controller:Faulty"/' \
      "$src/scenarios/paper/altitude_step.yaml" > "$tmp/sweep.yaml"
    grep -q 'python: "faulty_controller:Faulty"' "$tmp/sweep.yaml" || fail "the sweep scenario was not made"
    rc=0
    FAULTY_FAULT=raise FAULTY_AT=2 "$bin" sweep "$tmp/sweep.yaml" --vary "mass=grid(1.9,2.0)" --out "$tmp/sweep" \
      --no-plots > "$tmp/sweep.log" 2>&1 || rc=$?
    [ "$rc" = 5 ] || { cat "$tmp/sweep.log"; fail "sweep: exit $rc, expected 5"; }
    grep -q "the controller failed in 2 runs" "$tmp/sweep.log" || { cat "$tmp/sweep.log"; fail "sweep: no message"; }
    python3 - "$tmp/sweep/summary.json" <<'PY' || fail "sweep: summary.json does not name the controller's failure"
import json, sys
runs = json.load(open(sys.argv[1]))["per_run"]
assert len(runs) == 2 and all(r["error_cause"] == "controller" for r in runs), runs
assert all("at step 100 (t = 2 s): raised ValueError" in r["error"] for r in runs), runs
PY
    echo "sweep: exit 5, both runs' controller failure in summary.json" ;;
  python_isolation_bit_identical)  # the same bytes with the controller in its own process and in quadcosim's
    python_scenario 5
    run_expect 0
    mv "$tmp/out" "$tmp/isolated"
    QUADCOSIM_PYTHON_IN_PROCESS=1 run_expect 0
    cmp "$tmp/isolated/trajectory.csv" "$tmp/out/trajectory.csv" || fail "trajectory.csv differs in-process"
    echo "trajectory.csv identical ($(wc -l < "$tmp/out/trajectory.csv") lines) isolated and in-process" ;;
  *) echo "unknown case $case_name"; exit 2 ;;
esac
