#!/usr/bin/env bash
# Smoke tests of the quadcosim binary, one case per CTest test.
#   usage: cli_smoke.sh QUADCOSIM_BINARY SOURCE_DIR CASE
# Each case runs in a fresh temporary directory that is removed on exit, and fails with a message
# saying what was expected and what happened.
set -euo pipefail

if [[ $# -ne 3 ]]; then
  echo "usage: $0 QUADCOSIM_BINARY SOURCE_DIR CASE" >&2
  exit 2
fi
QC=$1
SRC=$2
CASE=$3

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

fail() {
  echo "FAIL [$CASE]: $*" >&2
  exit 1
}

# Runs "$@" with stdout and stderr captured in $TMP/out and $TMP/err; sets RC to its exit code.
run() {
  set +e
  "$@" >"$TMP/out" 2>"$TMP/err"
  RC=$?
  set -e
}

# Exit code must be exactly $1 for the command that follows.
expect_rc() {
  local want=$1
  shift
  run "$@"
  if [[ $RC -ne $want ]]; then
    echo "--- stdout:" >&2; cat "$TMP/out" >&2
    echo "--- stderr:" >&2; cat "$TMP/err" >&2
    fail "expected exit code $want from '$*', got $RC"
  fi
}

# The file $1 must contain the fixed string $2.
expect_contains() {
  if ! grep -qF -- "$2" "$1"; then
    echo "--- $1:" >&2; cat "$1" >&2
    fail "expected '$2' in $(basename "$1")"
  fi
}

# Value of column $2 in the last data row of CSV $1.
last_value() {
  awk -F, -v col="$2" '
    NR == 1 { for (i = 1; i <= NF; ++i) if ($i == col) c = i; if (!c) exit 3; next }
    { v = $c }
    END { if (c) print v }' "$1"
}

# Fails unless metrics.json $1 has top-level "passed" equal to $2 (true or false).
expect_passed() {
  local got
  got=$(python3 -c 'import json, sys; print(str(json.load(open(sys.argv[1]))["passed"]).lower())' "$1") ||
    fail "cannot parse $1 as JSON"
  [[ $got == "$2" ]] || fail "expected \"passed\": $2 in $1, got $got"
}

ALTITUDE=$SRC/scenarios/paper/altitude_step.yaml
REQUIRED_COLUMNS="t x y z vx vy vz qw qx qy qz roll pitch yaw p q r w1 w2 w3 w4 x_des y_des z_des roll_des pitch_des yaw_des"

case $CASE in
  run_altitude)
    expect_rc 0 "$QC" run "$ALTITUDE" --out "$TMP/run" --no-plots
    csv=$TMP/run/trajectory.csv
    [[ -f $csv ]] || fail "no trajectory.csv written"
    [[ -f $TMP/run/metrics.json ]] || fail "no metrics.json written"
    rows=$(($(wc -l <"$csv") - 1))
    [[ $rows -eq 1501 ]] || fail "expected 1501 data rows (ticks 0..1500) in trajectory.csv, got $rows"
    header=$(head -n 1 "$csv")
    for c in $REQUIRED_COLUMNS; do
      [[ ",$header," == *",$c,"* ]] || fail "column '$c' missing from header: $header"
    done
    # Every row has as many cells as the header.
    awk -F, 'NR == 1 { n = NF; next } NF != n { printf "row %d has %d cells, header %d\n", NR, NF, n; bad = 1; exit }
             END { exit bad }' "$csv" >&2 || fail "ragged trajectory.csv"
    [[ $(last_value "$csv" t) == 15 ]] || fail "last row t is $(last_value "$csv" t), expected 15"
    expect_passed "$TMP/run/metrics.json" true
    ;;

  run_deterministic)
    expect_rc 0 "$QC" run "$ALTITUDE" --out "$TMP/a" --no-plots
    expect_rc 0 "$QC" run "$ALTITUDE" --out "$TMP/b" --no-plots
    cmp "$TMP/a/trajectory.csv" "$TMP/b/trajectory.csv" || fail "two runs of the same scenario differ"
    # The same judgement (metrics.json besides its provenance, which names the --out of each run).
    /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/../lib/same_metrics.py" "$TMP/a/metrics.json" "$TMP/b/metrics.json" || fail "two runs give different metrics.json"
    ;;

  run_failing_criterion)
    # The paper's altitude step overshoots about 18 %; a spec (judged by default) of at most 1 %.
    sed 's/overshoot_pct: \[null, 25\]/overshoot_pct: [null, 1]/' "$ALTITUDE" >"$TMP/impossible.yaml"
    grep -qF 'overshoot_pct: [null, 1]' "$TMP/impossible.yaml" || fail "could not edit the criterion"
    expect_rc 1 "$QC" run "$TMP/impossible.yaml" --out "$TMP/run" --no-plots
    expect_passed "$TMP/run/metrics.json" false
    expect_contains "$TMP/out" FAIL
    ;;

  openloop_hover)
    # Four rotors at sqrt(m g / (4 kt)) carry the paper's vehicle: it stays at 5 m for 2 s.
    w=$(awk 'BEGIN { printf "%.17g", sqrt(1.96 * 9.81 / (4 * 2.06e-7)) }')
    printf 't,w1,w2,w3,w4\n0,%s,%s,%s,%s\n2,%s,%s,%s,%s\n' "$w" "$w" "$w" "$w" "$w" "$w" "$w" "$w" >"$TMP/hover.csv"
    expect_rc 0 "$QC" openloop --commands "$TMP/hover.csv" --out "$TMP/traj.csv" --initial-z 5
    rows=$(($(wc -l <"$TMP/traj.csv") - 1))
    [[ $rows -eq 201 ]] || fail "expected 201 rows (0..2 s at 100 Hz), got $rows"
    [[ $(last_value "$TMP/traj.csv" t) == 2 ]] || fail "last row t is $(last_value "$TMP/traj.csv" t), expected 2"
    awk -F, '
      NR == 1 { for (i = 1; i <= NF; ++i) { if ($i == "t") ct = i; if ($i == "z") cz = i } next }
      { d = $cz - 5; if (d < 0) d = -d
        if (d > 1e-6) { printf "t = %s: z = %s, expected 5 within 1e-6\n", $ct, $cz; bad = 1; exit } }
      END { exit bad }' "$TMP/traj.csv" >&2 || fail "hover does not hold z = 5"
    ;;

  openloop_freefall)
    # Rotors stopped: free fall from 10 m, z(t) = 10 - g t^2 / 2 (RK4 is exact for constant acceleration).
    printf 't,w1,w2,w3,w4\n0,0,0,0,0\n1,0,0,0,0\n' >"$TMP/zero.csv"
    expect_rc 0 "$QC" openloop --commands "$TMP/zero.csv" --out "$TMP/traj.csv" --initial-z 10
    [[ $(last_value "$TMP/traj.csv" t) == 1 ]] || fail "last row t is $(last_value "$TMP/traj.csv" t), expected 1"
    awk -F, '
      NR == 1 { for (i = 1; i <= NF; ++i) { if ($i == "t") ct = i; if ($i == "z") cz = i } next }
      { want = 10 - 9.81 / 2 * $ct * $ct; d = $cz - want; if (d < 0) d = -d
        if (d > 1e-6) { printf "t = %s: z = %s, expected %.9f within 1e-6\n", $ct, $cz, want; bad = 1; exit }
        last_t = $ct; last_z = $cz }
      END { if (bad) exit 1
            d = last_z - (10 - 9.81 / 2); if (d < 0) d = -d
            if (last_t != 1 || d > 1e-6) { printf "final z = %s at t = %s, expected 5.095\n", last_z, last_t; exit 1 } }' \
      "$TMP/traj.csv" >&2 || fail "free fall does not follow 10 - g t^2 / 2"
    ;;

  lqr)
    expect_rc 0 "$QC" lqr
    for axis in roll pitch yaw; do
      expect_contains "$TMP/out" "$axis axis"
    done
    [[ $(grep -c 'K = \[' "$TMP/out") -eq 3 ]] || { cat "$TMP/out" >&2; fail "expected a gain K for each of 3 axes"; }
    [[ $(grep -c 'closed-loop poles: ' "$TMP/out") -eq 3 ]] || { cat "$TMP/out" >&2; fail "expected poles for each of 3 axes"; }
    ;;

  bad_yaml)
    printf 'name: bad\nvehicle: {mass_kg: -1}\n' >"$TMP/bad.yaml"
    expect_rc 2 "$QC" run "$TMP/bad.yaml" --out "$TMP/run" --no-plots
    expect_contains "$TMP/err" "$TMP/bad.yaml"
    expect_contains "$TMP/err" "vehicle.mass_kg"
    expect_contains "$TMP/err" "-1"
    [[ ! -e $TMP/run/trajectory.csv ]] || fail "a trajectory was written for a rejected scenario"
    ;;

  missing_scenario)
    run "$QC" run "$TMP/no_such_scenario.yaml" --out "$TMP/run" --no-plots
    [[ $RC -ne 0 ]] || fail "expected a non-zero exit for a missing scenario file"
    [[ $RC -lt 128 ]] || fail "exit code $RC: killed by a signal instead of a clean error"
    expect_contains "$TMP/err" "no_such_scenario.yaml"
    ;;

  params)
    expect_rc 0 "$QC" params
    grep -qE '^z_des[[:space:]]' "$TMP/out" || { cat "$TMP/out" >&2; fail "z_des not listed by 'params'"; }
    ;;

  params_vehicle)
    # The vehicle table: Table 1's mass as its default, gravity's range open at 0, and docs/model.md
    # carrying exactly the table the binary prints (between its two marker lines).
    expect_rc 0 "$QC" params --vehicle
    grep -qE '^mass_kg[[:space:]]+kg[[:space:]]+\[1e-06, 1e\+12\][[:space:]]+1\.96[[:space:]]' "$TMP/out" ||
      { cat "$TMP/out" >&2; fail "mass_kg row of 'params --vehicle'"; }
    grep -qE '^gravity_m_s2[[:space:]]+m/s\^2[[:space:]]+\(0, 1000\][[:space:]]+9\.81[[:space:]]' "$TMP/out" ||
      { cat "$TMP/out" >&2; fail "gravity_m_s2 row of 'params --vehicle'"; }
    expect_rc 0 "$QC" params --vehicle --markdown
    sed -n '/<!-- vehicle-parameters:begin/,/<!-- vehicle-parameters:end/p' "$SRC/docs/model.md" | sed '1d;$d' \
      > "$TMP/doc_table"
    [ -s "$TMP/doc_table" ] || fail "docs/model.md has no vehicle-parameters block"
    diff -u "$TMP/doc_table" "$TMP/out" >&2 ||
      fail "docs/model.md's vehicle table differs from 'quadcosim params --vehicle --markdown' (paste its output)"
    ;;

  params_presets)
    # The ready vehicles: listed with their sources, one printed with its own values (the Crazyflie's
    # 27 g and Förster's product of inertia), the preset named in the scenario flying the circle, and
    # an unknown name refused as a usage error naming the known ones.
    expect_rc 0 "$QC" params --vehicle --list
    for p in paper crazyflie2 hummingbird f450 firefly; do
      grep -qE "^$p[[:space:]]" "$TMP/out" || { cat "$TMP/out" >&2; fail "preset $p not listed"; }
    done
    grep -q "System Identification of the Crazyflie 2.0" "$TMP/out" || fail "the crazyflie2 source is not listed"
    expect_rc 0 "$QC" params --vehicle --preset crazyflie2
    grep -qE '^mass_kg[[:space:]].*[[:space:]]0\.027[[:space:]]' "$TMP/out" || { cat "$TMP/out" >&2; fail "crazyflie2 mass"; }
    grep -qE '^Ixy_kg_m2[[:space:]].*[[:space:]]8\.30806e-07[[:space:]]' "$TMP/out" ||
      { cat "$TMP/out" >&2; fail "crazyflie2 Ixy"; }
    expect_rc 2 "$QC" params --vehicle --preset crazyfly
    grep -q "crazyflie2" "$TMP/err" || { cat "$TMP/err" >&2; fail "the refusal does not name the presets"; }
    expect_rc 0 "$QC" run "$SRC/scenarios/tracking/circle_se3_crazyflie2.yaml" --out "$TMP/cf" --no-plots
    grep -q "tracking from t = 12 s .*: PASS" "$TMP/cf/metrics.txt" || { cat "$TMP/cf/metrics.txt" >&2; fail "crazyflie2 circle"; }
    # The hexarotor preset on the same circle (six rotor columns), and a custom octorotor's step.
    expect_rc 0 "$QC" run "$SRC/scenarios/tracking/circle_se3_firefly.yaml" --out "$TMP/ff" --no-plots
    grep -q "tracking from t = 12 s .*: PASS" "$TMP/ff/metrics.txt" || { cat "$TMP/ff/metrics.txt" >&2; fail "firefly circle"; }
    head -1 "$TMP/ff/trajectory.csv" | grep -q ",w6,cmd1," || fail "firefly trajectory.csv has no w6 column"
    expect_rc 0 "$QC" run "$SRC/scenarios/examples/octo_custom_step.yaml" --out "$TMP/octo" --no-plots
    grep -q "hold from t = 10 s: PASS" "$TMP/octo/metrics.txt" || { cat "$TMP/octo/metrics.txt" >&2; fail "octorotor step"; }
    head -1 "$TMP/octo/trajectory.csv" | grep -q ",sat8,tilt_sat," || fail "octorotor trajectory.csv has no sat8 column"
    ;;

  *)
    echo "unknown case '$CASE'" >&2
    exit 2
    ;;
esac

echo "ok [$CASE]"
