#!/usr/bin/env bash
# A controller quadcosim has never seen (tests/newcomer/cascade.py, written as a newcomer would) and
# every registered type fly every shipped scenario: the scenarios say what is flown and judged, each
# controller type brings its own gains (docs/scenarios.md, "Any controller").
# Usage: newcomer_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID PYTHON_PACKAGE_DIR
# Cases: cli_types (every scenario x every registered type), cli_python (every scenario x the
# newcomer's class), python_module (the same from `import quadcosim`, trajectories identical to the
# CLI's), dds_python (the class as the DDS controller node in lockstep: identical to in-process).
# A run passes when it ends with exit 0 or 1 (1: a criterion of the scenario failed, which a
# controller that is not the scenario's own may do), with every tick of the run in trajectory.csv
# and every number finite. Cases needing Python exit 77 on a CLI built without it.
bin="$1"; src="$2"; pydir="${5:-}"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
py=/usr/bin/python3
export PYTHONPATH="$src/tests/newcomer${PYTHONPATH:+:$PYTHONPATH}"
scenarios=("$src"/scenarios/*/*.yaml)

# check_outputs SCENARIO FOLDER: every tick recorded (one vehicle's trajectory.csv, or each of a
# swarm's vehicles), every number finite.
check_outputs() {
  "$py" - "$1" "$2" <<'PY'
import csv, glob, math, os, re, sys
scenario, folder = sys.argv[1:3]
text = open(scenario).read()  # the shipped files write these two keys plainly, once
duration = re.search(r"^  duration_s: *([0-9.]+)", text, re.M)
rate = re.search(r"^  plant_rate_hz: *([0-9.]+)", text, re.M)
ticks = round(float(duration.group(1) if duration else 15) * float(rate.group(1) if rate else 100)) + 1
files = [os.path.join(folder, "trajectory.csv")]
if not os.path.exists(files[0]):
    files = sorted(glob.glob(os.path.join(folder, "uav*", "trajectory.csv")))
assert files, f"no trajectory.csv in {folder}: {os.listdir(folder)}"
for f in files:
    rows = list(csv.DictReader(open(f)))
    assert len(rows) == ticks, (f, len(rows), ticks)
    for r in rows:
        for k in ("x", "y", "z", "vx", "vy", "vz", "qw"):
            assert math.isfinite(float(r[k])), (f, r["t"], k, r[k])
PY
}

# fly CONTROLLER: every shipped scenario with --controller CONTROLLER.
fly() {
  local c="$1" s out rc
  for s in "${scenarios[@]}"; do
    out="$tmp/$(echo "$c" | tr ':' '_')/$(basename "$(dirname "$s")")_$(basename "$s" .yaml)"
    mkdir -p "$(dirname "$out")"
    set +e
    "$bin" run "$s" --controller "$c" --out "$out" --no-plots > "$out.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -le 1 ] || { tail -5 "$out.log"; fail "$s with --controller $c: exit $rc"; }
    check_outputs "$s" "$out" || fail "$s with --controller $c: outputs"
    echo "ok: $c flies $(basename "$s") (exit $rc)"
  done
}

case "$case_name" in
  cli_types)
    mapfile -t types < <("$bin" params --list | awk 'NR > 1 {print $1}')
    [ "${#types[@]}" -ge 3 ] || fail "expected at least paper, se3 and example_pd: ${types[*]}"
    for t in "${types[@]}"; do fly "$t"; done
    ;;

  cli_python)
    skip_without_python "$bin"
    fly python:cascade:Cascade
    # Its altitude loop is a PD on a double integrator (thrust tilt-compensated, level flight):
    # z'' = kp (z_des - z) - kd z', damping kd / (2 sqrt(kp)) = 0.8 at the defaults, so a step
    # overshoots by exp(-pi zeta / sqrt(1 - zeta^2)) = 1.52 % (motors and the 50 Hz loop shift it a little).
    "$py" - "$tmp/python_cascade_Cascade/paper_altitude_step/metrics.json" <<'PY'
import json, math, sys
m = json.load(open(sys.argv[1]))
overshoot = m["steps"][0]["figures"]["overshoot_pct"]
zeta = 3.2 / (2 * math.sqrt(4.0))
expected = 100 * math.exp(-math.pi * zeta / math.sqrt(1 - zeta * zeta))
print(f"altitude step overshoot {overshoot:.3f} %, a PD with damping {zeta}: {expected:.3f} %")
assert abs(overshoot - expected) <= 0.3, (overshoot, expected)
PY
    ;;

  python_module)
    skip_without_python "$bin"
    [ -d "$pydir" ] || { echo "SKIP: the Python module was not built ($pydir)"; exit 77; }
    for s in "$src/scenarios/paper/altitude_step.yaml" "$src/scenarios/tracking/circle_se3.yaml" \
             "$src/scenarios/realism/hover_wind_gusts.yaml"; do
      name="$(basename "$s" .yaml)"
      set +e
      "$bin" run "$s" --controller python:cascade:Cascade --out "$tmp/cli_$name" --no-plots > "$tmp/cli_$name.log" 2>&1
      rc=$?
      set -e
      [ "$rc" -le 1 ] || fail "$s: CLI exit $rc"
      PYTHONPATH="$pydir:$PYTHONPATH" "$py" - "$s" "$tmp/py_$name" <<'PY' || fail "$s from Python"
import sys
import quadcosim
from cascade import Cascade
result = quadcosim.run(sys.argv[1], out=sys.argv[2], controller=Cascade)
print(sys.argv[1], "flown from Python:", result)
PY
      cmp "$tmp/cli_$name/trajectory.csv" "$tmp/py_$name/trajectory.csv" ||
        fail "$s: the CLI's and Python's trajectories differ"
      echo "ok: $name from the CLI and from Python, trajectory.csv identical"
    done
    ;;

  dds_python)
    skip_without_python "$bin"
    s="$src/scenarios/paper/altitude_step.yaml"
    set +e
    "$bin" run "$s" --controller python:cascade:Cascade --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1
    rc_in=$?
    timeout 300 "$bin" run "$s" --controller python:cascade:Cascade --transport dds --out "$tmp/dds" --no-plots \
      > "$tmp/dds.log" 2>&1
    rc_dds=$?
    set -e
    [ "$rc_in" -le 1 ] && [ "$rc_dds" = "$rc_in" ] || { tail -20 "$tmp/dds.log"; fail "exit $rc_in in process, $rc_dds over DDS"; }
    cmp "$tmp/in/trajectory.csv" "$tmp/dds/trajectory.csv" || fail "the DDS lockstep run differs from in-process"
    echo "ok: the newcomer's class as the DDS controller node, trajectory.csv identical to in-process"
    ;;

  *) fail "unknown case" ;;
esac
