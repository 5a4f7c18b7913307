#!/usr/bin/env bash
# FMUs in quadcosim's runs. Usage: fmi_runs_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# The round trips export quadcosim's plant (or controller) for a scenario with `quadcosim fmu
# export`, fly the scenario again with the FMU in its place and compare trajectory.csv with the
# native run's. Cases that need `quadcosim fmu export` exit 77 (skipped) on a build without it.
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
paper="$src/scenarios/paper"

need_export() {
  "$bin" fmu export --help > /dev/null 2>&1 || { echo "SKIP: this build has no 'quadcosim fmu export'"; exit 77; }
}

# $1 scenario file, $2 plant|controller, $3 output .fmu, then further export flags (--fmi 3)
export_fmu() {
  "$bin" fmu export "$2" --scenario "$1" --out "$3" "${@:4}" > "$tmp/export_$2.log" 2>&1 || fail "fmu export $2 failed"
}

# The scenario $1 with `$2` (a YAML mapping line) appended, written to $3.
with_key() { { cat "$1"; echo; echo "$2"; } > "$3"; }

# The paper experiment $1 with its exported plant FMU as the plant: trajectory.csv byte-identical to
# the native run's (and the metrics: they are computed from it). $2: extra run flags.
plant_round_trip() {
  local s="$1"; shift
  need_export
  export_fmu "$paper/$s.yaml" plant "$tmp/plant.fmu" ${QUADCOSIM_EXPORT_FLAGS:-}
  with_key "$paper/$s.yaml" "plant: {fmu: plant.fmu}" "$tmp/fmu_$s.yaml"
  "$bin" run "$paper/$s.yaml" --out "$tmp/native" --no-plots > "$tmp/native.log" 2>&1 || fail "native run failed"
  "$bin" run "$tmp/fmu_$s.yaml" --out "$tmp/fmu" --no-plots "$@" > "$tmp/fmu.log" 2>&1 || fail "FMU plant run failed"
  cmp "$tmp/native/trajectory.csv" "$tmp/fmu/trajectory.csv" || fail "$s: trajectory.csv differs with the FMU plant"
  [ "$(wc -l < "$tmp/fmu/trajectory.csv")" -gt 500 ] || fail "trajectory too short"
  echo "$s: trajectory.csv byte-identical with the exported plant FMU ${*:-in-process}"
}

# A vehicle with more than four rotors, $1 a scenario file, its exported plant FMU (omega_cmd[1..N]) as
# the plant: trajectory.csv byte-identical to the native run's, rotor columns w1..wN and cmd1..cmdN
# included; $2: the rotor count the FMU must declare; further arguments: export flags (--fmi 3).
plant_round_trip_rotors() {
  local s="$1" n="$2"; shift 2
  need_export
  export_fmu "$s" plant "$tmp/plant.fmu" "$@"
  python3 - "$tmp/plant.fmu" "$n" <<'PY' || fail "$(basename "$s"): the plant FMU does not have $n rotor commands"
import re, sys, zipfile
xml = zipfile.ZipFile(sys.argv[1]).read("modelDescription.xml").decode()
names = re.findall(r'name="(omega_cmd\[\d+\])"', xml)
assert names == [f"omega_cmd[{i}]" for i in range(1, int(sys.argv[2]) + 1)], names
PY
  with_key "$s" "plant: {fmu: plant.fmu}" "$tmp/fmu.yaml"
  "$bin" run "$s" --out "$tmp/native" --no-plots > "$tmp/native.log" 2>&1 || fail "native run failed"
  "$bin" run "$tmp/fmu.yaml" --out "$tmp/fmu" --no-plots > "$tmp/fmu.log" 2>&1 || fail "FMU plant run failed: $(tail -3 "$tmp/fmu.log")"
  head -1 "$tmp/fmu/trajectory.csv" | grep -q ",w$n,cmd1," || fail "trajectory.csv has no w$n column"
  cmp "$tmp/native/trajectory.csv" "$tmp/fmu/trajectory.csv" || fail "$(basename "$s"): trajectory.csv differs with the FMU plant"
  echo "$(basename "$s"): trajectory.csv byte-identical with its $n-rotor plant FMU ${*:-(FMI 2)}"
}

# The paper altitude step with the exported paper controller as the controller. The state, rotor
# speed, command, setpoint and flag columns (t .. cmd4, x_des .. z_des, safety, watchdog) must be
# byte-identical; the other status columns (U, the tracked attitude, the saturation flags, att_err)
# come from the FMU master's defaults, as the exported controller outputs only omega_cmd
# (docs/scenarios.md).
controller_round_trip() {
  need_export
  export_fmu "$paper/altitude_step.yaml" controller "$tmp/controller.fmu"
  # The node's setpoints and schedule stay the scenario's; the FMU replaces the controller.
  sed 's/^controller:$/controller:\n  fmu: controller.fmu/' "$paper/altitude_step.yaml" > "$tmp/fmu_ctl.yaml"
  grep -q 'fmu: controller.fmu' "$tmp/fmu_ctl.yaml" || fail "could not write the scenario"
  "$bin" run "$paper/altitude_step.yaml" --out "$tmp/native" --no-plots > "$tmp/native.log" 2>&1 \
    || fail "native run failed"
  "$bin" run "$tmp/fmu_ctl.yaml" --out "$tmp/fmu" --no-plots > "$tmp/fmu.log" 2>&1 || fail "FMU controller run failed"
  local cols; cols="$(head -1 "$tmp/native/trajectory.csv" | tr ',' '\n' | grep -n -E '^(t|x|y|z|vx|vy|vz|qw|qx|qy|qz|roll|pitch|yaw|p|q|r|w[1-4]|cmd[1-4]|x_des|y_des|z_des|safety|watchdog)$' | cut -d: -f1 | paste -sd,)"
  [ -n "$cols" ] || fail "no state columns found in $(head -1 "$tmp/native/trajectory.csv")"
  cmp <(cut -d, -f"$cols" "$tmp/native/trajectory.csv") <(cut -d, -f"$cols" "$tmp/fmu/trajectory.csv") \
    || fail "state columns ($cols) differ with the FMU controller"
  echo "altitude_step: columns $cols byte-identical with the exported controller FMU"
}


# The columns of trajectory.csv that the plant and the controller's command make (t .. cmdN) and the
# node's flags: what must match when only the controller is an FMU (see controller_round_trip).
state_columns() {
  head -1 "$1" | tr ',' '\n' | grep -n -E '^(t|x|y|z|vx|vy|vz|qw|qx|qy|qz|roll|pitch|yaw|p|q|r|w[1-8]|cmd[1-8]|safety|watchdog)$' \
    | cut -d: -f1 | paste -sd,
}

# The tracking figure $2 (position_rmse_m, position_max_m) [m] in $1/metrics.json, with all 17 digits.
tracking_figure() {
  python3 -c 'import json,sys; print(repr(json.load(open(sys.argv[1]))["tracking"]["figures"][sys.argv[2]]))' \
    "$1/metrics.json" "$2"
}

# A tracking scenario $1 (scenarios/tracking/NAME) exported as a controller FMU (further export flags
# after it) and flown back with --controller fmu:...: the FMU carries the trajectory and flies it as
# the native controller does, so trajectory.csv is byte-identical (the reference columns x_des ..
# included: the master's node computes them from the same scenario) and so is the tracking RMSE in
# metrics.json. Before the FMU carried the trajectory it flew the circle in attitude mode: RMSE 2.97 m.
controller_trajectory_round_trip() {
  local s="$1"; shift
  need_export
  export_fmu "$src/scenarios/tracking/$s.yaml" controller "$tmp/controller.fmu" "$@"
  grep -q "reference: .* (carried in the FMU; ref.external = true takes the ref.\* inputs instead)" \
    "$tmp/export_controller.log" || fail "the export did not say it carries the trajectory"
  ! grep -q "not part of the FMU" "$tmp/export_controller.log" || fail "the export still says the trajectory is left out"
  "$bin" run "$src/scenarios/tracking/$s.yaml" --out "$tmp/native" --no-plots > "$tmp/native.log" 2>&1 \
    || fail "native run failed"
  "$bin" run "$src/scenarios/tracking/$s.yaml" --controller "fmu:$tmp/controller.fmu" --out "$tmp/fmu" --no-plots \
    > "$tmp/fmu.log" 2>&1 || fail "FMU controller run failed"
  [ "$(wc -l < "$tmp/fmu/trajectory.csv")" -gt 1000 ] || fail "trajectory too short"
  local cols; cols="$(state_columns "$tmp/native/trajectory.csv"),$(head -1 "$tmp/native/trajectory.csv" | tr ',' '\n' | grep -n -E '^(x_des|y_des|z_des)$' | cut -d: -f1 | paste -sd,)"
  cmp <(cut -d, -f"$cols" "$tmp/native/trajectory.csv") <(cut -d, -f"$cols" "$tmp/fmu/trajectory.csv") \
    || fail "$s: columns $cols differ with the exported controller FMU"
  # What the controller tracked and its own figures: the FMU outputs them, quadcosim reads them by name.
  python3 - "$tmp/native/trajectory.csv" "$tmp/fmu/trajectory.csv" <<'PY' || fail "$s: tracked attitude or figures differ"
import csv, sys
native, fmu = (list(csv.DictReader(open(f))) for f in sys.argv[1:3])
figures = [c for c in native[0] if c.startswith("out.")]
assert figures and all(c in fmu[0] for c in figures), (figures, list(fmu[0]))
assert len(native) == len(fmu)
for a, b in zip(native, fmu):
    for c in ["roll_des", "pitch_des", "yaw_des", "tilt_sat"] + figures:
        assert a[c] == b[c], (a["t"], c, a[c], b[c])
print(f"roll_des, pitch_des, yaw_des, tilt_sat and {len(figures)} figures of the controller identical")
PY
  local figure native fmu
  for figure in position_max_m position_rmse_m; do
    native="$(tracking_figure "$tmp/native" $figure)"; fmu="$(tracking_figure "$tmp/fmu" $figure)"
    [ "$native" = "$fmu" ] || fail "$s: tracking $figure $fmu with the FMU, $native natively"
  done
  # The scenario's own specification (5 cm RMSE): the attitude-mode FMU missed it by metres.
  python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) < 0.05 else 1)' "$fmu" || fail "$s: RMSE $fmu m >= 0.05 m"
  echo "$s: columns $cols byte-identical with the exported controller FMU ${*:-(FMI 2)}; tracking RMSE $fmu m both"
}

# What wins: the trajectory the FMU carries, unless ref.external is true. The FMU exported from
# circle_se3 (r = 2 m) flies in a scenario whose circle is r = 3 m: by default it flies its own r = 2 m
# circle (the master's r = 3 m reference inputs are ignored); with parameters {ref.external: true} it flies the master's r = 3 m reference (the columns
# of the native r = 3 m run, reference columns included).
controller_trajectory_external() {
  need_export
  local circle="$src/scenarios/tracking/circle_se3.yaml"
  export_fmu "$circle" controller "$tmp/controller.fmu"
  sed 's/^  radius_m: 2$/  radius_m: 3/; s/^  position_m: \[2, 0, 5\]$/  position_m: [3, 0, 5]/' "$circle" > "$tmp/r3.yaml"
  grep -q 'radius_m: 3' "$tmp/r3.yaml" && grep -q 'position_m: \[3, 0, 5\]' "$tmp/r3.yaml" || fail "could not write r3.yaml"
  sed 's/^  type: se3$/  fmu: controller.fmu/' "$tmp/r3.yaml" > "$tmp/r3_embedded.yaml"
  sed 's/^  type: se3$/  fmu: controller.fmu\n  parameters: {ref.external: true}/' "$tmp/r3.yaml" > "$tmp/r3_external.yaml"
  grep -q 'ref.external: true' "$tmp/r3_external.yaml" || fail "could not write r3_external.yaml"
  for run in native_r3:"$tmp/r3.yaml" external:"$tmp/r3_external.yaml"; do
    "$bin" run "${run#*:}" --out "$tmp/${run%%:*}" --no-plots > "$tmp/${run%%:*}.log" 2>&1 || fail "run ${run%%:*} failed"
  done
  # Judged against the scenario's r = 3 m circle, the FMU's own r = 2 m one fails the 5 cm spec: exit 1.
  local rc=0
  "$bin" run "$tmp/r3_embedded.yaml" --out "$tmp/embedded" --no-plots > "$tmp/embedded.log" 2>&1 || rc=$?
  [ "$rc" = 1 ] || fail "the embedded run exited $rc, expected 1 (its r = 2 m circle fails the r = 3 m spec)"
  # With ref.external the FMU flies what the master feeds: the native r = 3 m run's columns. By default
  # it flies its own circle from the r = 3 m scenario's start (3, 0, 5): the state differs from the
  # native r = 3 m run's, and after the spin-up and the first lap the vehicle is on the r = 2 m circle.
  local cols; cols="$(state_columns "$tmp/native_r3/trajectory.csv")"
  local all; all="$cols,$(head -1 "$tmp/native_r3/trajectory.csv" | tr ',' '\n' | grep -n -E '^(x_des|y_des|z_des)$' | cut -d: -f1 | paste -sd,)"
  cmp <(cut -d, -f"$all" "$tmp/native_r3/trajectory.csv") <(cut -d, -f"$all" "$tmp/external/trajectory.csv") \
    || fail "ref.external: true did not fly the master's reference as the native run does"
  if cmp -s <(cut -d, -f"$cols" "$tmp/native_r3/trajectory.csv") <(cut -d, -f"$cols" "$tmp/embedded/trajectory.csv"); then
    fail "the FMU flew the master's r = 3 m reference: its own trajectory did not win"
  fi
  python3 - "$tmp/embedded/trajectory.csv" <<'PYEOF' || fail "the embedded run did not fly the r = 2 m circle"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
late = [r for r in rows if float(r["t"]) >= 12.0]  # after the spin-up and the first lap
radii = [math.hypot(float(r["x"]), float(r["y"])) for r in late]
worst = max(abs(radius - 2.0) for radius in radii)
print(f"embedded: distance from the centre {min(radii):.4f} .. {max(radii):.4f} m over t >= 12 s")
sys.exit(0 if worst < 0.05 else 1)
PYEOF
  # The two circles share centre, phase and period: 1 m apart, which is what tracking measures.
  local rmse; rmse="$(tracking_figure "$tmp/embedded" position_rmse_m)"
  python3 -c 'import sys; sys.exit(0 if abs(float(sys.argv[1]) - 1.0) < 0.05 else 1)' "$rmse" \
    || fail "the embedded run's RMSE against the r = 3 m circle is $rmse m, expected 1 m"
  echo "ref.external true: the master's r = 3 m reference, columns byte-identical with the native run;"
  echo "default: the FMU's own r = 2 m circle (RMSE $rmse m against the master's r = 3 m reference)"
}

case "$case_name" in
  plant_round_trip_altitude) plant_round_trip altitude_step ;;
  plant_round_trip_roll) plant_round_trip roll_step ;;
  plant_round_trip_pitch) plant_round_trip pitch_step ;;
  plant_round_trip_yaw) plant_round_trip yaw_step ;;
  plant_round_trip_dds) plant_round_trip altitude_step --transport dds ;;
  plant_round_trip_fmi3) QUADCOSIM_EXPORT_FLAGS="--fmi 3" plant_round_trip pitch_step ;;  # FMI 3.0 through the master
  controller_round_trip) controller_round_trip ;;
  controller_trajectory_circle) controller_trajectory_round_trip circle_se3 ;;
  controller_trajectory_waypoints_fmi3) controller_trajectory_round_trip waypoints_se3 --fmi 3 ;;
  controller_trajectory_external) controller_trajectory_external ;;
  plant_round_trip_hexarotor) plant_round_trip_rotors "$src/scenarios/tracking/circle_se3_firefly.yaml" 6 ;;
  plant_round_trip_octorotor_fmi3) plant_round_trip_rotors "$src/scenarios/examples/octo_custom_step.yaml" 8 --fmi 3 ;;
  controller_trajectory_hexarotor) controller_trajectory_round_trip circle_se3_firefly ;;
  node_fmu_flags)  # `plant --fmu` and `controller --fmu` over DDS lockstep: the native trajectory again
    need_export
    export_fmu "$paper/altitude_step.yaml" plant "$tmp/plant.fmu"
    export_fmu "$paper/altitude_step.yaml" controller "$tmp/controller.fmu"
    "$bin" run "$paper/altitude_step.yaml" --out "$tmp/native" --no-plots > "$tmp/native.log" 2>&1 \
      || fail "native run failed"
    "$bin" controller --scenario "$paper/altitude_step.yaml" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$paper/altitude_step.yaml" --fmu "$tmp/plant.fmu" --record "$tmp/plant.csv" \
      > "$tmp/plant.log" 2>&1 || fail "plant --fmu failed"
    grep -q "plant: FMU plant.fmu" "$tmp/plant.log" || fail "the plant did not say it flies the FMU"
    cmp "$tmp/native/trajectory.csv" "$tmp/plant.csv" || fail "plant --fmu: trajectory differs"
    kill "${pids[0]}" 2>/dev/null || true
    # Both FMUs, each in its own process: the state columns as natively (see controller_round_trip).
    "$bin" controller --scenario "$paper/altitude_step.yaml" --fmu "$tmp/controller.fmu" > "$tmp/controller2.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$paper/altitude_step.yaml" --fmu "$tmp/plant.fmu" --record "$tmp/both.csv" \
      > "$tmp/plant2.log" 2>&1 || fail "plant --fmu with controller --fmu failed"
    grep -q "controller fmu " "$tmp/controller2.log" || fail "the controller did not say it flies the FMU"
    cmp <(cut -d, -f1-28 "$tmp/native/trajectory.csv") <(cut -d, -f1-28 "$tmp/both.csv") \
      || fail "plant --fmu with controller --fmu: state columns differ"
    echo "plant --fmu (and controller --fmu) over DDS lockstep: trajectory (state columns) byte-identical"
    ;;
  swarm_and_sweep)  # one FMU instance per vehicle; a sweep pushes each run's vehicle into the FMU
    need_export
    export_fmu "$paper/altitude_step.yaml" plant "$tmp/plant.fmu"
    with_key "$paper/altitude_step.yaml" "plant: {fmu: plant.fmu}" "$tmp/fmu.yaml"
    "$bin" run "$tmp/fmu.yaml" --vehicles 4 --out "$tmp/swarm" --no-plots > "$tmp/swarm.log" 2>&1 \
      || fail "FMU swarm failed"
    "$bin" run "$paper/altitude_step.yaml" --vehicles 4 --out "$tmp/swarm_native" --no-plots \
      > "$tmp/swarm_native.log" 2>&1 || fail "native swarm failed"
    cmp "$tmp/swarm/vehicles.csv" "$tmp/swarm_native/vehicles.csv" || fail "swarm final states differ"
    echo "4-vehicle swarm: final states byte-identical with one plant FMU instance each"
    # A sweep over the mass: each run's vehicle goes into the FMU as vehicle.mass_kg.
    local_sweep() {
      "$bin" sweep "$1" --runs 3 --seed 7 --vary mass=10% --keep all --min-pass-rate 0 --out "$2" \
        > "$2.log" 2>&1 || fail "sweep of $1 failed"
    }
    local_sweep "$tmp/fmu.yaml" "$tmp/sweep_fmu"
    local_sweep "$paper/altitude_step.yaml" "$tmp/sweep_native"
    for r in 0000 0001 0002; do
      cmp "$tmp/sweep_fmu/runs/$r/trajectory.csv" "$tmp/sweep_native/runs/$r/trajectory.csv" \
        || fail "sweep run $r differs with the FMU plant"
    done
    if cmp -s "$tmp/sweep_fmu/runs/0000/trajectory.csv" "$tmp/sweep_fmu/runs/0001/trajectory.csv"; then
      fail "the drawn masses changed nothing"
    fi
    echo "3-run mass sweep: every run byte-identical with the FMU plant"
    ;;
  *) fail "unknown case" ;;
esac
