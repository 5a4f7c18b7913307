#!/usr/bin/env bash
# A controller quadcosim has never seen (tests/newcomer/cascade.py, written as a newcomer would) and
# every registered type fly every shipped scenario: the scenarios say what is flown and judged, each
# controller type brings its own gains (docs/scenarios.md, "Any controller").
# Usage: newcomer_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID PYTHON_PACKAGE_DIR
# Cases: cli_types (every scenario x every registered type), cli_python (every scenario x the
# newcomer's class), python_module (the same from `import quadcosim`, trajectories identical to the
# CLI's, every shipped scenario, the swarm's vehicles.csv and recorded vehicles too), dds_python (the class as the DDS
# controller node in lockstep: identical to in-process),
# reports (what the class does, its declared outputs, tilt setpoint and saturation, is in the record).
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
    for s in "${scenarios[@]}"; do
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
      if grep -q "^swarm:" "$s"; then  # a swarm: every vehicle's end and each recorded vehicle's run
        files=(vehicles.csv)
        for d in "$tmp/cli_$name"/uav*/; do files+=("$(basename "$d")/trajectory.csv"); done
        [ "${#files[@]}" -ge 2 ] || fail "$s: the CLI recorded no vehicle"
      else
        files=(trajectory.csv)
      fi
      for f in "${files[@]}"; do
        cmp "$tmp/cli_$name/$f" "$tmp/py_$name/$f" || fail "$s: the CLI's and Python's $f differ"
      done
      echo "ok: $name from the CLI and from Python, ${files[*]} identical"
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

  reports)  # what the newcomer's class does is in the record: its figures, its tilt, its saturation
    skip_without_python "$bin"
    s="$src/scenarios/tracking/circle_se3.yaml"
    set +e
    "$bin" run "$s" --controller python:cascade:Cascade --out "$tmp/circle" > "$tmp/circle.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -le 1 ] || { tail -5 "$tmp/circle.log"; fail "circle: exit $rc"; }
    "$py" - "$tmp/circle" "$src" <<'PY' || fail "circle: what the controller did is not in the record"
import csv, json, math, os, re, sys
run, src = sys.argv[1:3]
rows = list(csv.DictReader(open(os.path.join(run, "trajectory.csv"))))
header = list(rows[0].keys())
assert header[-3:] == ["out.thrust_N", "out.roll_des", "out.pitch_des"], header[-4:]
# The tilt the class asks for (its outputs roll_des, pitch_des) is the recorded setpoint, row by row.
for r in rows:
    for a in ("roll_des", "pitch_des"):
        assert r[a] == r["out." + a], (r["t"], a, r[a], r["out." + a])
roll_des = [float(r["roll_des"]) for r in rows]
amplitude = max(map(abs, roll_des))
assert amplitude > 0.02, amplitude  # the circle needs a tilt: the setpoint is not a flat 0
# ... and the vehicle flies it: roll follows roll_des to within a fraction of its swing.
late = [r for r in rows if float(r["t"]) >= 3.0]
rms = math.sqrt(sum((float(r["roll"]) - float(r["roll_des"])) ** 2 for r in late) / len(late))
print(f"roll_des up to {amplitude:.4f} rad; roll - roll_des RMS {rms:.4f} rad after 3 s")
assert rms < 0.3 * amplitude, (rms, amplitude)
# thrust_N is the class's collective thrust: the wrench of the commanded speeds (U1 = k_t sum cmd^2)
# wherever no rotor sits at a limit (k_t of the scenario's vehicle, Table 1 unless it says otherwise).
k_t = 2.06e-7
text = open(os.path.join(run, "scenario.yaml")).read()
m = re.search(r"kt_N_per_rad2_s2: *([0-9.eE+-]+)", text)
if m:
    k_t = float(m.group(1))
for r in rows[1:]:
    if any(r[f"sat{i}"] == "1" for i in range(1, 5)) or r["safety"] == "1":
        continue
    u1 = float(r["U1"])
    assert abs(u1 - float(r["out.thrust_N"])) <= 1e-6 * u1, (r["t"], u1, r["out.thrust_N"])
metrics = json.load(open(os.path.join(run, "metrics.json")))
assert "command_at_limit_s" in metrics["saturation"]["figures"], metrics["saturation"]
report = open(os.path.join(run, "report.html")).read()
assert "The controller&#x27;s own figures" in report or "The controller's own figures" in report
assert "out.&lt;name&gt;" in report and "thrust_N" in report
assert os.path.getsize(os.path.join(run, "outputs.png")) > 10000
print("ok: circle flown by the newcomer's class: its tilt setpoint, thrust and outputs recorded")
PY
    # Rotors pushed to their limit: the paper's climb with motors of 6000 rad/s (hover needs 4830). The
    # class clips at omega_max; what it commands is measured at the plant whatever it reports.
    s="$tmp/weak_motors.yaml"
    { cat "$src/scenarios/paper/altitude_step.yaml"; printf 'vehicle:\n  motor:\n    omega_max_rad_s: 6000\n'; } > "$s"
    set +e
    "$bin" run "$s" --controller python:cascade:Cascade --out "$tmp/motor" --no-plots > "$tmp/motor.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -le 1 ] || { tail -5 "$tmp/motor.log"; fail "weak motors: exit $rc"; }
    "$py" - "$tmp/motor" <<'PY' || fail "weak motors: saturation not measured"
import csv, json, os, re, sys
run = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(run, "trajectory.csv"))))
text = open(os.path.join(run, "scenario.yaml")).read()
m = re.search(r"omega_max_rad_s: *([0-9.eE+-]+)", text)
omega_max = float(m.group(1)) if m else 12000.0
period = float(rows[1]["t"]) - float(rows[0]["t"])
# Independently of quadcosim's figures: rows where the controller (not the safety command or the
# watchdog) had some rotor commanded at omega_max or beyond, or at 0 (the default omega_min) or below.
def at_limit(r):
    if r["safety"] == "1" or r["watchdog"] == "1" or r["U1"] == "nan":
        return False
    return any(float(r[f"cmd{i}"]) >= omega_max or float(r[f"cmd{i}"]) <= 0.0 for i in range(1, 5))
expected = period * sum(1 for r in rows if at_limit(r))
figures = json.load(open(os.path.join(run, "metrics.json")))["saturation"]["figures"]
print(f"command at a limit {figures['command_at_limit_s']:.3f} s (counted here {expected:.3f} s); "
      f"the class's rotors at a limit {figures['saturated_s']:.3f} s")
assert expected > 0.1, expected
assert abs(figures["command_at_limit_s"] - expected) <= 1e-9, (figures["command_at_limit_s"], expected)
assert figures["saturated_s"] > 0.1, figures  # its flags: its commands at the limits, no longer 0
PY
    grep -q "warning: rotor saturation" "$tmp/motor.log" || { cat "$tmp/motor.log"; fail "no saturation warning"; }
    echo "ok: the newcomer's saturation measured at the plant and flagged from its commands"
    ;;

  *) fail "unknown case" ;;
esac
