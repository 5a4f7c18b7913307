#!/usr/bin/env bash
# Trajectory tracking judged end to end (analysis.tracking), one case per CTest test.
#   usage: tracking_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
S="$SRC/scenarios/tracking/circle_se3.yaml"

case "$CASE" in
  circle_passes)  # figures, criteria and verdict in metrics.json and metrics.txt; att_err last in the CSV
    "$QC" run "$S" --out "$TMP/run" > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "circle_se3 failed its criteria"; }
    grep -q "^tracking from t = 12 s (901 samples, at the controller's steps every 0.02 s): PASS" "$TMP/run/metrics.txt" \
      || { cat "$TMP/run/metrics.txt"; fail "no tracking verdict in metrics.txt"; }
    for f in tracking_path.png tracking_axes.png tracking_error.png; do
      [ -s "$TMP/run/$f" ] || fail "$f not written"
      grep -q ">$f<" "$TMP/run/report.html" || fail "$f not in report.html"
    done
    "$PY" - "$TMP/run" <<'PYEOF' || fail "metrics.json / trajectory.csv content"
import csv, json, math, sys
run = sys.argv[1]
m = json.load(open(run + "/metrics.json"))
tr = m["tracking"]
assert tr["after_s"] == 12 and tr["reference_period_s"] == 0.02 and tr["samples"] == 901, tr
names = ["position_rmse_m", "position_max_m", "x_rmse_m", "x_max_m", "y_rmse_m", "y_max_m", "z_rmse_m", "z_max_m",
         "yaw_rmse_rad", "attitude_error_rmse", "attitude_error_max"]
assert sorted(tr["figures"]) == sorted(names), list(tr["figures"])
assert all(isinstance(tr["figures"][n], float) for n in names), tr["figures"]
assert [c["figure"] for c in tr["criteria"]] == ["position_rmse_m", "position_max_m"]
assert all(c["passed"] for c in tr["criteria"]) and tr["passed"] is True and m["passed"] is True
# Recompute the RMSE from trajectory.csv: rows at t >= 12 s on the controller's 50 Hz steps.
rows = list(csv.DictReader(open(run + "/trajectory.csv")))
columns = list(rows[0])
own = [c for c in columns if c.startswith("out.")]  # the controller's own figures come last
assert columns[len(columns) - len(own) - 1] == "att_err", "att_err is not the last column before out.*"
assert own == ["out." + n for n in ("e_x.x", "e_x.y", "e_x.z", "e_v.x", "e_v.y", "e_v.z", "e_R.x", "e_R.y", "e_R.z",
                                    "e_Omega.x", "e_Omega.y", "e_Omega.z", "thrust", "yaw_torque_cut")], own
sq = [sum((float(r[a + "_des"]) - float(r[a])) ** 2 for a in "xyz") for r in rows
      if float(r["t"]) >= 12 and round(float(r["t"]) * 100) % 2 == 0]
assert len(sq) == 901
rmse = math.sqrt(sum(sq) / len(sq))
assert abs(rmse - tr["figures"]["position_rmse_m"]) <= 1e-12 * max(1.0, rmse), (rmse, tr["figures"])
assert rmse < 0.05
assert all(math.isfinite(float(r["att_err"])) for r in rows), "se3 reports an attitude error every step"
PYEOF
    ;;

  too_strict_fails)  # a criterion the run cannot meet fails it: exit 1, FAIL in metrics.json and metrics.txt
    sed 's/position_rmse_m: \[null, 0.05\]/position_rmse_m: [null, 1.0e-6]/' "$S" > "$TMP/strict.yaml"
    set +e
    "$QC" run "$TMP/strict.yaml" --out "$TMP/run" --no-plots > "$TMP/log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 1 ] || { cat "$TMP/log"; fail "exit $rc, expected 1 (a criterion failed)"; }
    grep -q "^tracking from t = 12 s .*: FAIL" "$TMP/run/metrics.txt" || fail "no FAIL in metrics.txt"
    grep -Eq "^  position_rmse_m +[0-9.e-]+ +\[-, 1e-06\] +FAIL" "$TMP/run/metrics.txt" \
      || { cat "$TMP/run/metrics.txt"; fail "the failed criterion is not shown"; }
    "$PY" - "$TMP/run/metrics.json" <<'PYEOF' || fail "metrics.json verdict"
import json, sys
m = json.load(open(sys.argv[1]))
c = {x["figure"]: x for x in m["tracking"]["criteria"]}
assert c["position_rmse_m"]["passed"] is False and c["position_rmse_m"]["max"] == 1e-6
assert c["position_max_m"]["passed"] is True
assert m["tracking"]["passed"] is False and m["passed"] is False
PYEOF
    ;;

  bad_keys)  # bad analysis.tracking input: exit 2, naming the file, key and value
    check() {  # check SED_EXPRESSION EXPECTED_TEXT
      sed "$1" "$S" > "$TMP/bad.yaml"
      set +e
      "$QC" run "$TMP/bad.yaml" --out "$TMP/out_$RANDOM" --no-plots > "$TMP/log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -eq 2 ] || { cat "$TMP/log"; fail "$1: exit $rc, expected 2"; }
      grep -qF -- "$2" "$TMP/log" || { cat "$TMP/log"; fail "$1: message lacks '$2'"; }
      grep -qF "bad.yaml" "$TMP/log" || fail "$1: message does not name the file"
    }
    check 's/position_max_m:/position_p99_m:/' "analysis.tracking.spec.position_p99_m"
    check 's/position_max_m:/position_p99_m:/' "unknown tracking figure"
    check 's/after_s: 12 /after_s: 99 /' "analysis.tracking.after_s"
    check 's/position_max_m: \[null, 0.1\]/position_max_m: [0.2, 0.1]/' "min is above max"
    check 's/position_max_m: \[null, 0.1\]/position_max_m: [null, fast]/' "fast"
    check 's/    after_s: 12 /    after_s: 12\n    window_s: 3 /' "window_s"
    ;;

  *) fail "unknown case $CASE" ;;
esac
