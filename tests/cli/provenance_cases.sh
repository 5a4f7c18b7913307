#!/usr/bin/env bash
# Provenance in every run folder, and runs compared by what flew (docs/outputs.md, "Provenance",
# "Comparing runs"). One case per CTest test; the expected values (hashes, host, version, the
# controller named on the command line) are computed here, independently of quadcosim.
#   usage: provenance_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
CIRCLE="$SRC/scenarios/tracking/circle_se3.yaml"
ALT="$SRC/scenarios/paper/altitude_step.yaml"

# run SCENARIO OUT [ARGS...]: `quadcosim run`, which may exit 0 (passed) or 1 (a criterion failed).
run() {
  local scenario="$1" out="$2"
  shift 2
  local rc=0
  "$QC" run "$scenario" --out "$out" "$@" > "$out.log" 2>&1 || rc=$?
  [ "$rc" -le 1 ] || { cat "$out.log"; fail "run $scenario $* exited $rc"; }
}

case "$CASE" in
  controller_override)  # --controller other than the file's: the flying one everywhere
    run "$CIRCLE" "$TMP/pd" --controller example_pd
    "$PY" - "$TMP/pd" "$CIRCLE" "$(sha256sum "$CIRCLE" | cut -c1-64)" "$(hostname)" "$("$QC" --version)" <<'PYEOF' \
      || fail "the flying controller is not recorded"
import json, re, sys, yaml
run, scenario_file, sha, host, version = sys.argv[1:]
m = json.load(open(run + "/metrics.json"))
p = m["provenance"]
c = p["controller"]
assert c["type"] == "example_pd" and c["label"] == "example_pd", c
assert c["scenario_type"] == "se3" and c["override"] == "example_pd", c
assert isinstance(c["parameters"], dict) and c["parameters"], c
assert p["transport"] == "inproc" and p["clock"] == "lockstep", p
assert p["command_line"][1:3] == ["run", scenario_file] and "--controller" in p["command_line"], p["command_line"]
assert p["command_line"][p["command_line"].index("--controller") + 1] == "example_pd"
assert p["host"] == host, (p["host"], host)
assert "quadcosim " + p["quadcosim_version"] == version, (p["quadcosim_version"], version)
assert p["git_commit"] == "unknown" or re.fullmatch(r"[0-9a-f]{40}", p["git_commit"]), p["git_commit"]
assert p["scenario"]["file"] == scenario_file and p["scenario"]["sha256"] == sha, p["scenario"]
# The effective scenario: the file's, with the controller that flew.
eff = yaml.safe_load(open(run + "/scenario.yaml"))
assert eff["controller"]["type"] == "example_pd", eff["controller"]
assert eff["trajectory"]["kind"] == "circle" and eff["name"] == "circle_se3"
# metadata.yaml: the bag description for ros2 bag, and the same record beside it.
meta = yaml.safe_load(open(run + "/metadata.yaml"))
assert meta["rosbag2_bagfile_information"]["storage_identifier"] == "mcap"
assert meta["quadcosim_provenance"] == p, (meta["quadcosim_provenance"], p)
# The report: the controller near the top, the description marked as the file's, the headline first.
page = open(run + "/report.html", encoding="utf-8").read()
assert "flown by controller <b>example_pd</b>" in page
assert page.index('id="flown"') < page.index('id="verdict"') < page.index('id="provenance"')
assert "written for its own controller" in page
assert "<td>example_pd (in place of the scenario file&#x27;s se3)</td>" in page, "provenance block"
rmse = m["tracking"]["figures"]["position_rmse_m"]
assert f"position tracking RMSE {rmse:.4g} m" in page
h2 = [mm.start() for mm in re.finditer("<h2", page)]
assert page.index('id="tracking"') == h2[0] + len("<h2 "), "the tracking section is not the first"
assert page.index(">tracking_path.png<") < page.index(">overview.png<")
PYEOF
    # Without --controller, scenario.yaml is the file itself, byte for byte.
    run "$CIRCLE" "$TMP/se3" --no-plots
    cmp "$CIRCLE" "$TMP/se3/scenario.yaml" || fail "scenario.yaml differs from the file without --controller"
    "$PY" -c 'import json,sys; c=json.load(open(sys.argv[1]))["provenance"]["controller"];
assert c["type"] == "se3" and c["override"] is None and c["scenario_type"] == "se3", c' "$TMP/se3/metrics.json" \
      || fail "the file's controller is not recorded as such"
    ;;

  python_controller)  # a Python class: module:Class, its module file and that file's SHA-256
    if "$QC" controller --python "no_such_module_for_the_check:X" > "$TMP/check.log" 2>&1; then :; fi
    if grep -q "built without Python" "$TMP/check.log"; then
      echo "SKIP: this quadcosim was built without Python"
      exit 77
    fi
    mkdir "$TMP/s"
    cp "$SRC/tests/python_node/altitude_pd.py" "$TMP/s/"
    sed -e '/^analysis:/,$d' -e 's/^  duration_s: .*/  duration_s: 3/' \
      -e 's/^controller:$/controller:\n  python: "altitude_pd:AltitudePD"/' "$ALT" > "$TMP/s/pd.yaml"
    grep -q 'python: "altitude_pd:AltitudePD"' "$TMP/s/pd.yaml" || fail "could not write the scenario"
    run "$TMP/s/pd.yaml" "$TMP/py" --no-plots
    "$PY" - "$TMP/py" "$(realpath "$TMP/s/altitude_pd.py")" "$(sha256sum "$TMP/s/altitude_pd.py" | cut -c1-64)" <<'PYEOF' \
      || fail "the Python controller is not recorded"
import json, sys, yaml
run, module_file, sha = sys.argv[1:]
p = json.load(open(run + "/metrics.json"))["provenance"]
c = p["controller"]
assert c["type"] == "python" and c["label"] == "python altitude_pd:AltitudePD", c
assert c["python"] == {"target": "altitude_pd:AltitudePD", "module_file": module_file, "sha256": sha}, c["python"]
assert c["parameters"]["kp_z"] == 4.0 and c["parameters"]["kd_z"] == 3.0, c["parameters"]
assert yaml.safe_load(open(run + "/metadata.yaml"))["quadcosim_provenance"] == p
PYEOF
    ;;

  fmu_controller)  # an FMU as the controller: its path and the SHA-256 of the .fmu file
    "$QC" fmu export controller --out "$TMP/c.fmu" > "$TMP/export.log" 2>&1 || { cat "$TMP/export.log"; fail "fmu export"; }
    sed "s|^controller:\$|controller:\n  fmu: $TMP/c.fmu|" "$ALT" > "$TMP/fmu.yaml"
    run "$TMP/fmu.yaml" "$TMP/f" --no-plots
    "$PY" - "$TMP/f" "$(realpath "$TMP/c.fmu")" "$(sha256sum "$TMP/c.fmu" | cut -c1-64)" <<'PYEOF' \
      || fail "the FMU controller is not recorded"
import json, sys
run, path, sha = sys.argv[1:]
c = json.load(open(run + "/metrics.json"))["provenance"]["controller"]
assert c["type"] == "fmu" and c["scenario_type"] == "fmu" and c["label"] == "fmu c.fmu", c
assert c["fmu"] == {"path": path, "sha256": sha}, c["fmu"]
PYEOF
    ;;

  sweep_runs)  # each run of a sweep records what flew
    "$QC" sweep "$ALT" --runs 2 --seed 3 --vary mass=5% --min-pass-rate 0 --no-plots --out "$TMP/s" > "$TMP/log" 2>&1 \
      || { cat "$TMP/log"; fail "sweep failed"; }
    for r in 0000 0001; do
      "$PY" - "$TMP/s/runs/$r/metrics.json" "$(sha256sum "$ALT" | cut -c1-64)" <<'PYEOF' || fail "run $r has no provenance"
import json, sys
p = json.load(open(sys.argv[1]))["provenance"]
assert p["controller"]["type"] == "paper" and p["transport"] == "inproc", p
assert p["command_line"][1] == "sweep" and p["scenario"]["sha256"] == sys.argv[2], p
PYEOF
    done
    "$PY" -c 'import json, sys; s = json.load(open(sys.argv[1]))
assert "provenance" not in s and all("provenance" not in r for r in s["per_run"])' "$TMP/s/summary.json" \
      || fail "summary.json has a provenance: it would differ between shards"
    ;;

  summary_controllers)  # one scenario, two controllers: two rows each naming its controller; a step run too
    run "$CIRCLE" "$TMP/a" --no-plots
    run "$CIRCLE" "$TMP/b" --no-plots --controller example_pd
    run "$ALT" "$TMP/alt" --no-plots
    set +e
    "$QC" summary "$TMP/a" "$TMP/b" "$TMP/alt" --out "$TMP/table.md" > "$TMP/out" 2> "$TMP/err"
    rc=$?
    set -e
    [ "$rc" -eq 1 ] || { cat "$TMP/out" "$TMP/err"; fail "summary exited $rc, expected 1 (run b fails its criteria)"; }
    "$PY" - "$TMP" <<'PYEOF' || { cat "$TMP/out"; fail "summary rows"; }
import json, sys
tmp = sys.argv[1]
lines = open(tmp + "/out").read().splitlines()
table = open(tmp + "/table.md").read()
assert "paper" not in table.splitlines()[0].lower(), "the title speaks of the paper"
# | run | controller | judged | what | figure | value | reference | spec | paper | verdict |
rows = [[c.strip() for c in l.strip("|").split("|")] for l in lines[2:]]
def rows_of(run, figure):
    return [r for r in rows if r[0] == run and r[4] == figure]
for run, controller in ((tmp + "/a", "se3"), (tmp + "/b", "example_pd")):
    m = json.load(open(run + "/metrics.json"))["tracking"]["figures"]
    rmse = rows_of(run, "position RMSE m")
    assert len(rmse) == 1 and rmse[0][1] == controller and rmse[0][2] == "spec", rmse
    assert rmse[0][3] == "tracking from t = 12 s" and rmse[0][5] == f"{m['position_rmse_m']:.4g}", rmse
    mx = rows_of(run, "position max m")
    assert len(mx) == 1 and mx[0][5] == f"{m['position_max_m']:.4g}", mx
assert rows_of(tmp + "/a", "position RMSE m")[0][9] == "pass"
assert rows_of(tmp + "/b", "position RMSE m")[0][9] == "**FAIL**"
over = rows_of(tmp + "/alt", "overshoot %")
assert len(over) == 1 and over[0][1] == "paper" and over[0][3] == "z step 0 → 10", over
PYEOF
    ;;

  compare_tracking)  # two tracking runs: the paths and errors overlaid, figures side by side
    run "$CIRCLE" "$TMP/se3" --no-plots
    run "$CIRCLE" "$TMP/pd" --no-plots --controller example_pd
    "$QC" compare "$TMP/se3" "$TMP/pd" --out "$TMP/cmp" > "$TMP/cmp.md" 2> "$TMP/err" || { cat "$TMP/err"; fail "compare failed"; }
    for f in compare_tracking_path.png compare_tracking_error.png; do
      [ -s "$TMP/cmp/$f" ] || fail "compare wrote no $f"
      head -c 8 "$TMP/cmp/$f" | od -An -tx1 | grep -q "89 50 4e 47" || fail "$f is not a PNG"
      [ "$(stat -c %s "$TMP/cmp/$f")" -gt 20000 ] || fail "$f is nearly empty"
    done
    "$PY" - "$TMP" <<'PYEOF' || { cat "$TMP/cmp.md"; fail "compare table"; }
import json, sys
tmp = sys.argv[1]
md = open(tmp + "/cmp.md").read()
assert md == open(tmp + "/cmp/compare.md").read()
assert md.splitlines()[0] == "# Run figures: A = se3 (se3, circle_se3), B = pd (example_pd, circle_se3)", md.splitlines()[0]
a = json.load(open(tmp + "/se3/metrics.json"))["tracking"]["figures"]["position_rmse_m"]
b = json.load(open(tmp + "/pd/metrics.json"))["tracking"]["figures"]["position_rmse_m"]
row = [l for l in md.splitlines() if l.startswith("| position_rmse_m |")]
assert row == [f"| position_rmse_m | {a:.4g} | {b:.4g} | {b - a:+.4g} |"], row
PYEOF
    ;;

  *) fail "unknown case $CASE" ;;
esac
echo "ok: $CASE"
