#!/usr/bin/env bash
# Bad input to every command: a table of (expected exit code, fragments the error must contain,
# command line). Each error must name what was wrong (file, key or flag, the value, what was
# expected) and exit with the code the README gives: 2 for bad input (3 when an output cannot be
# written). No case may reach the network or wait: flags and files are checked first.
#   usage: bad_input.sh QUADCOSIM_BINARY SOURCE_DIR
set -euo pipefail
QC=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$TMP"
export ROS_DOMAIN_ID=$((166 + ${QUADCOSIM_TEST_DOMAIN_OFFSET:-0})) ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
ALT=$SRC/scenarios/paper/altitude_step.yaml

# Inputs.
printf 'vehicle: {mass_kg: heavy}\n' > wrong_type.yaml
printf 'name: [\n  broken\n' > syntax.yaml
printf 'simulaton: {duration_s: 1}\n' > unknown_key.yaml
printf 'simulation: {plant_rate_hz: -5}\n' > out_of_range.yaml
printf 'controller:\n  roll_des: 5\n' > param_range.yaml
printf 'altitude: {kq: 3}\n' > params_unknown.yaml
printf 'mass_kg: 1.0\nlayout: h\n' > vehicle_bad.yaml
printf 'controller: {type: lqg}\n' > controller_type.yaml
printf 'controller: {paper: {lqr: {roll: {q_angel: 2}}}}\n' > type_section_typo.yaml
printf 'controller:\n  type: se3\n  lqr: {roll: {r: 1}}\n' > controller_foreign_key.yaml
printf 'controller:\n  type: se3\n  k_R: {x: -1}\n' > controller_gain_range.yaml
printf 'controller: {z_des: 1}\nschedule:\n  - at_s: 1\n    set: {type: se3}\n' > controller_type_change.yaml
printf 'mass_kg: .nan\n' > vehicle_nan.yaml
printf 'vehicle: {mass_kg: "1.2"}\n' > quoted_mass.yaml
printf "simulation: {duration_s: '10'}\n" > quoted_duration.yaml
printf '? [a, b]\n: 1\n' > list_key.yaml
printf 'vehicle: {preset: firefly}\ncontroller: {sitl: {firmware: ardupilot, binary: /bin/true}}\n' > sitl_hex.yaml
printf 'layout: hex_x\nspin: [1, 1, 1, 1, 1, 1]\n' > hex_singular.yaml
printf 't,w1,w2,w3,w4\n0,1,2,3\n' > short.csv
printf 't,w1,w2,w3,w4\n0,1,nan,3,4\n' > nan.csv
printf 'time,a,b,c,d\n0,1,2,3,4\n' > header.csv
printf 't,w1,w2,w3,w4\n0,1,2,3,4\n' > ok.csv
mkdir -p not_a_run no_metrics
printf 't\n0\n' > no_metrics/trajectory.csv

failures=0
cases=0
# expect RC "FRAGMENT;;FRAGMENT..." ARGS...
expect() {
  local want=$1 fragments=$2
  shift 2
  cases=$((cases + 1))
  set +e
  timeout 30 "$QC" "$@" > out.txt 2> err.txt
  local rc=$?
  set -e
  local text
  text="$(cat out.txt err.txt)"
  local problem=""
  [ "$rc" -eq "$want" ] || problem="exit $rc, expected $want"
  local IFS_save=$IFS
  IFS=$'\n'
  for f in $(printf '%s' "$fragments" | sed 's/;;/\n/g'); do
    [[ "$text" == *"$f"* ]] || problem="$problem${problem:+; }'$f' missing"
  done
  IFS=$IFS_save
  if [ -n "$problem" ]; then
    failures=$((failures + 1))
    echo "FAIL: quadcosim $*: $problem"
    echo "  output: $(head -c 600 <<< "$text")"
  fi
}

# Command line
expect 2 "unknown command 'frobnicate';;expected a command: run" frobnicate
expect 2 "unknown option '--bogus'" --bogus
expect 2 "A subcommand is required"

# run
expect 2 "scenario: File does not exist: missing.yaml" run missing.yaml --out o
expect 2 "--out is required" run "$ALT"
expect 2 "wrong_type.yaml: vehicle.mass_kg: got 'heavy', expected a number in [1e-06, 1e+12]" run wrong_type.yaml --out o --no-plots
expect 2 "syntax.yaml: line 3: YAML syntax error" run syntax.yaml --out o --no-plots
expect 2 "unknown_key.yaml: simulaton: unknown key" run unknown_key.yaml --out o --no-plots
expect 2 "out_of_range.yaml: simulation.plant_rate_hz: got '-5', expected a number in [0.001, 1e+06]" run out_of_range.yaml --out o --no-plots
expect 2 "param_range.yaml: controller.roll_des: roll_des must be in [-1.5, 1.5] rad, got 5" run param_range.yaml --out o --no-plots
expect 2 "list_key.yaml: got a list as a key, expected a plain name" run list_key.yaml --out o --no-plots
expect 2 "controller_type.yaml: controller.type: got 'lqg', expected one of;;paper;;se3" run controller_type.yaml --out o --no-plots
expect 2 "controller_foreign_key.yaml: controller.lqr.roll.r: unknown parameter 'lqr.roll.r' of the node or of controller type 'se3'" run controller_foreign_key.yaml --out o --no-plots
expect 2 "controller_gain_range.yaml: controller.k_R.x: k_R.x must be in [0, 1e+09] N m/rad, got -1" run controller_gain_range.yaml --out o --no-plots
expect 2 "controller_type_change.yaml: schedule[0].set.type: the controller's type cannot change during a run" run controller_type_change.yaml --out o --no-plots
expect 2 "--controller: got 'lqg', expected a controller type (paper, se3, example_pd), python:MODULE:CLASS" run "$ALT" --out o --controller lqg
expect 2 "--controller: got 'python:nocolon', expected python:MODULE:CLASS" run "$ALT" --out o --controller python:nocolon
expect 2 "--controller: got 'fmu:no_such.fmu': no such file 'no_such.fmu'" run "$ALT" --out o --controller fmu:no_such.fmu
# A misspelt gain of a type that does not fly is still refused, at its key.
expect 2 "type_section_typo.yaml: controller.paper.lqr.roll.q_angel: unknown parameter 'lqr.roll.q_angel' of the node or of controller type 'paper'" run type_section_typo.yaml --out o --no-plots --controller se3
expect 2 "--controller: got 'lqg', expected a controller type (paper, se3, example_pd), python:MODULE:CLASS" params --controller lqg
expect 2 "--controller: got 'se4';;did you mean 'se3'?" params --controller se4
expect 2 "--controller: got 'lqg', expected a controller type (paper, se3, example_pd)" controller --controller lqg
expect 2 "--transport: carrier not in {inproc,dds}" run "$ALT" --out o --transport carrier
expect 2 "--timeout: Value abc not in range 0.01" run "$ALT" --out o --timeout abc
expect 2 "--rate-factor: Value 0 not in range 0.001" run "$ALT" --out o --rate-factor 0
expect 2 "run: unknown option '--fast'" run "$ALT" --out o --fast
# An unknown option is named as unknown, with the nearest known one, also when a required option or
# argument is missing too (CLI11 alone reports the missing one: "--out is required").
expect 2 "run: unknown option '--outt'; did you mean '--out'?" run "$ALT" --outt o
expect 2 "run: unknown option '--outt'; did you mean '--out'?" run --outt o
expect 2 "run: unknown option '--no-plot'; did you mean '--no-plots'?" run "$ALT" --out o --no-plot
expect 2 "params: unknown option '--contrler'; did you mean '--controller'?" params --contrler se3
expect 2 "plant: unknown option '--sceanrio'; did you mean '--scenario'?" plant --sceanrio "$ALT"
expect 2 "get: unknown option '--timout'; did you mean '--timeout'?" param get /attitude_controller z_des --timout 1
# A number in quotes is text, refused with the key, the file and the value as written.
expect 2 "quoted_mass.yaml: vehicle.mass_kg: \"1.2\" is a string; write 1.2 without quotes" run quoted_mass.yaml --out o --no-plots
expect 2 "quoted_duration.yaml: simulation.duration_s: \"10\" is a string; write 10 without quotes" run quoted_duration.yaml --out o --no-plots
# A misspelt key or parameter: the nearest known name.
expect 2 "unknown_key.yaml: simulaton: unknown key; did you mean 'simulation'?" run unknown_key.yaml --out o --no-plots
expect 2 "params_unknown.yaml: altitude.kq: unknown parameter 'altitude.kq';;did you mean 'altitude.kp'?" controller --params params_unknown.yaml
expect 3 "cannot create output directory /proc/quadcosim_no" run "$ALT" --out /proc/quadcosim_no --no-plots
for f in --realtime --pin "--timeout 5" "--keystore ks"; do
  # shellcheck disable=SC2086
  expect 2 "${f%% *}: does nothing with --transport inproc" run "$ALT" --out o $f
done
expect 2 "--rate-factor: does nothing with lockstep" run "$ALT" --out o --transport dds --rate-factor 2
expect 2 "--threads: does nothing with --transport dds" run "$ALT" --out o --transport dds --threads 2

# plant and controller (checked before any DDS entity is created)
expect 2 "--scenario: File does not exist: missing.yaml" plant --scenario missing.yaml
expect 2 "--cpus: 'x' is not a CPU list;;bad item 'x'" plant --cpus x
expect 2 "--cpus: '0,2-1' is not a CPU list;;bad item '2-1'" controller --cpus 0,2-1
expect 2 "error: controller: --cpus: CPUs 1000 refused" controller --cpus 1000
expect 2 "wrong_type.yaml: vehicle.mass_kg: got 'heavy'" plant --scenario wrong_type.yaml
expect 2 "vehicle_bad.yaml: layout: got 'h', expected one of 'plus' 'x'" plant --vehicle vehicle_bad.yaml
expect 2 "vehicle_nan.yaml: mass_kg: got '.nan', expected a number" plant --vehicle vehicle_nan.yaml
expect 2 "--namespace: a namespace must start with '/', got 'drone'" plant --namespace drone
expect 2 "--duration: Value -1 not in range 0" plant --duration -1
expect 2 "--on-timeout: explode not in {abort,hold}" plant --on-timeout explode
expect 2 "--params: File does not exist: missing.yaml" controller --params missing.yaml
expect 2 "params_unknown.yaml: altitude.kq: unknown parameter 'altitude.kq' of the node or of controller type 'paper'" controller --params params_unknown.yaml
expect 2 "--namespace: a namespace may not contain '//', got '/a//b'" controller --namespace /a//b
expect 2 "--node-name: invalid ROS node name '1ctl'" controller --node-name 1ctl
expect 2 "--rate-factor: Value -2 not in range" controller --rate-factor -2

# param and topic
expect 2 "node is required" param get
expect 2 "node: invalid ROS node name '9node'" param get 9node z_des
expect 2 "value is required" param set /attitude_controller z_des
expect 2 "--timeout: Value -1 not in range" param get /attitude_controller z_des --timeout -1
expect 2 "topic is required" topic echo
expect 2 "--count: Value -3 not in range 1" topic echo /drone/Pose --count -3
expect 2 "--qos: fancy not in {default,sensor,transient_local}" topic echo /drone/Pose --qos fancy
expect 2 "--window: Value 0 not in range 1" topic hz /drone/Pose --window 0
expect 2 "--wait: Value soon not in range" topic list --wait soon

# record
expect 2 "--out is required" record
expect 2 "--namespace: a namespace must start with '/', got 'uav'" record --out r.mcap --namespace uav
expect 2 "--topics: cannot record '/nope'" record --out r.mcap --topics /nope
expect 2 "--duration: Value x not in range" record --out r.mcap --duration x

# plot, compare, summary
expect 2 "run_dir: Directory does not exist: missing_dir" plot missing_dir
expect 2 "run_dir: not_a_run is not a run directory (no trajectory.csv" plot not_a_run
expect 2 "run_dir: no_metrics is not a run directory (no metrics.json" plot no_metrics
expect 2 "run_b: Directory does not exist: missing_dir" compare not_a_run missing_dir
expect 2 "run_a: not_a_run is not a run directory" compare not_a_run not_a_run
expect 2 "not_a_run/metrics.json: cannot open" summary not_a_run
expect 2 "run_dirs is required" summary

# lqr, openloop, params
expect 2 "param_range.yaml: controller.roll_des: unknown parameter 'controller.roll_des' of the node or of controller type 'paper'" lqr --params param_range.yaml
expect 2 "vehicle_bad.yaml: layout: got 'h'" lqr --vehicle vehicle_bad.yaml
# Vehicles with other rotor counts: a singular rotor set, and the paths that fly quadrotors only.
expect 2 "hex_singular.yaml: spin: ;;layout hex_x leaves the mixer singular" lqr --vehicle hex_singular.yaml
# A hexarotor's FMUs (omega_cmd[1..6]) with the paper's quadrotor: both rotor counts named.
"$QC" fmu export plant --scenario "$SRC/scenarios/tracking/circle_se3_firefly.yaml" --out ff.fmu > /dev/null
"$QC" fmu export controller --scenario "$SRC/scenarios/tracking/circle_se3_firefly.yaml" --out ffc.fmu > /dev/null
{ cat "$ALT"; echo; echo "plant: {fmu: ff.fmu}"; } > alt_ff.yaml
expect 2 "alt_ff.yaml: plant.fmu: ff.fmu: the FMU plant takes 6 rotor speed commands (omega_cmd[1..6]);;the vehicle has 4 rotors (layout plus)" run alt_ff.yaml --out o --no-plots
expect 2 "controller.fmu: ffc.fmu: the FMU controller outputs 6 rotor speed commands (omega_cmd[1..6]);;the vehicle has 4 rotors (layout plus)" run "$ALT" --controller fmu:ffc.fmu --out o --no-plots
expect 2 "layout hex_x with 6 rotors;;quadrotor frames only" run sitl_hex.yaml --out sitl_hex --no-plots
expect 2 "--commands: File does not exist: missing.csv" openloop --commands missing.csv --out t.csv
expect 2 "short.csv:2: expected 5 values (t,w1,w2,w3,w4), got 4" openloop --commands short.csv --out t.csv
expect 2 "nan.csv:2: values must be finite" openloop --commands nan.csv --out t.csv
expect 2 "header.csv:1: header is 'time,a,b,c,d', expected t,w1,w2,w3,w4" openloop --commands header.csv --out t.csv
expect 2 "--substeps: Value 0 not in range 1" openloop --commands ok.csv --out t.csv --substeps 0
expect 2 "--rate-hz: Value fast not in range" openloop --commands ok.csv --out t.csv --rate-hz fast
expect 3 "/proc/quadcosim_no.csv: cannot open for writing" openloop --commands ok.csv --out /proc/quadcosim_no.csv
expect 2 "The following argument was not expected: extra" params extra

echo "$((cases - failures)) passed, $failures failed"
[ "$failures" -eq 0 ]
