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

case "$case_name" in
  plant_round_trip_altitude) plant_round_trip altitude_step ;;
  plant_round_trip_roll) plant_round_trip roll_step ;;
  plant_round_trip_pitch) plant_round_trip pitch_step ;;
  plant_round_trip_yaw) plant_round_trip yaw_step ;;
  plant_round_trip_dds) plant_round_trip altitude_step --transport dds ;;
  plant_round_trip_fmi3) QUADCOSIM_EXPORT_FLAGS="--fmi 3" plant_round_trip pitch_step ;;  # FMI 3.0 through the master
  controller_round_trip) controller_round_trip ;;
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
