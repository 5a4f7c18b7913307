#!/usr/bin/env bash
# `quadcosim sweep` beyond one batch of runs: rerun, shards and merge, kept trajectories, keys by
# their YAML path, output folder hygiene, the console table. One case per CTest test.
#   usage: sweep_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
HOVER="$SRC/scenarios/realism/hover_wind_gusts.yaml"
ALT="$SRC/scenarios/paper/altitude_step.yaml"

case "$CASE" in
  rerun)  # `sweep rerun DIR I` flies run I again: the outputs of `run`, the very figures of per_run
    "$QC" sweep "$HOVER" --runs 3 --seed 5 --vary mass=10% --vary controller.altitude.kd=uniform\(2,3.5\) \
      --vary environment.gusts.w20_m_s=normal\(7,1\) --vary controller.lqr.roll.q_angle=grid\(1,2\) \
      --min-pass-rate 0 --no-plots --out "$TMP/s" > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "sweep failed"; }
    for i in 0 4; do
      "$QC" sweep rerun "$TMP/s" $i --out "$TMP/r$i" --no-plots > "$TMP/log$i" 2>&1 || [ $? -eq 1 ] || { cat "$TMP/log$i"; fail "rerun $i failed"; }
      for f in trajectory.csv run.mcap metadata.yaml metrics.json metrics.txt scenario.yaml; do
        [ -s "$TMP/r$i/$f" ] || fail "rerun $i wrote no $f"
      done
      "$PY" - "$TMP/s/summary.json" "$TMP/r$i/metrics.json" "$TMP/s/runs/000$i/metrics.json" $i <<'PYEOF' || fail "rerun $i differs from the sweep"
import json, sys
s = json.load(open(sys.argv[1])); m = json.load(open(sys.argv[2])); k = json.load(open(sys.argv[3])); i = int(sys.argv[4])
run = s["per_run"][i]
assert run["index"] == i
figs = {"hold." + n: v for n, v in m["hold"]["figures"].items()}
# Floats as JSON shortest round-trip text: equal here means equal bit for bit.
assert figs == run["figures"], (figs, run["figures"])
assert m["passed"] == run["passed"]
for d in (m, k):
    assert d["sweep"]["seed"] == run["seed"] and d["sweep"]["values"] == run["values"], d["sweep"]
    assert d["sweep"]["index"] == i and d["sweep"]["sweep_seed"] == 5
v = m["sweep"]["vehicle"]["vehicle.mass_kg"]
assert v["controller_designed_for"] == s["vary"][0]["keys"][0]["nominal"] and v["flown"] == run["values"]["vehicle.mass_kg"]
assert sorted(run["values"]) == ["controller.altitude.kd", "controller.lqr.roll.q_angle",
                                 "environment.gusts.w20_m_s", "vehicle.mass_kg"], run["values"]
assert run["values"]["controller.lqr.roll.q_angle"] == (1.0 if i < 3 else 2.0)
PYEOF
    done
    set +e
    "$QC" sweep rerun "$TMP/s" 6 --out "$TMP/r6" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "run 6 is not in" "$TMP/o" || fail "rerun of a run the sweep lacks (rc $rc)"
    "$QC" sweep rerun "$TMP/nothing" 0 --out "$TMP/r7" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "not a sweep folder" "$TMP/o" || fail "rerun of a folder that is no sweep (rc $rc)"
    "$QC" sweep rerun "$TMP/s" 0 --out "$TMP/r0" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "is not empty" "$TMP/o" || fail "rerun into a used folder (rc $rc)"
    set -e
    ;;

  shard_merge)  # shards joined give the unsharded summary.json byte for byte (random + LHS, grid)
    A=(--runs 7 --seed 21 --vary mass=10% --vary controller.altitude.kd=normal\(2.7,0.3\) --sampler lhs --min-pass-rate 0 --no-plots)
    "$QC" sweep "$HOVER" "${A[@]}" --out "$TMP/all" > /dev/null 2>&1 || fail "unsharded sweep"
    for k in 1 2 3; do "$QC" sweep "$HOVER" "${A[@]}" --shard $k/3 --out "$TMP/p$k" --jobs 1 > /dev/null 2>&1 || fail "shard $k"; done
    [ ! -e "$TMP/p1/summary.json" ] && [ -s "$TMP/p1/shard.json" ] || fail "a shard writes shard.json, not summary.json"
    ls "$TMP/p2/runs" | tr '\n' ' ' | grep -qx "0001 0004 " || fail "shard 2/3 ran other runs than 1 and 4: $(ls "$TMP/p2/runs")"
    "$QC" sweep merge "$TMP/m" "$TMP/p3" "$TMP/p1" "$TMP/p2" --no-plots --min-pass-rate 0 > /dev/null || fail "merge"
    cmp "$TMP/all/summary.json" "$TMP/m/summary.json" || fail "merged summary.json differs from the unsharded one"
    G=(--vary controller.altitude.kp=grid\(3,4,5\) --vary controller.altitude.kd=linspace\(2,3,2\) --seed 4 --min-pass-rate 0 --no-plots)
    "$QC" sweep "$HOVER" "${G[@]}" --out "$TMP/gall" > /dev/null 2>&1 || fail "grid sweep"
    for k in 1 2; do "$QC" sweep "$HOVER" "${G[@]}" --shard $k/2 --out "$TMP/g$k" > /dev/null 2>&1 || fail "grid shard $k"; done
    "$QC" sweep merge "$TMP/gm" "$TMP/g1" "$TMP/g2" --no-plots --min-pass-rate 0 > /dev/null || fail "grid merge"
    cmp "$TMP/gall/summary.json" "$TMP/gm/summary.json" || fail "merged grid summary.json differs"
    "$PY" - "$TMP/gall/summary.json" <<'PYEOF' || fail "grid content"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["runs"] == 6, s["runs"]
pts = [(r["values"]["controller.altitude.kp"], r["values"]["controller.altitude.kd"]) for r in s["per_run"]]
assert pts == [(3, 2), (3, 3), (4, 2), (4, 3), (5, 2), (5, 3)], pts
PYEOF
    set +e
    "$QC" sweep merge "$TMP/m2" "$TMP/p1" "$TMP/p2" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "run 2 is missing" "$TMP/o" || fail "merge without shard 3 (rc $rc)"
    "$QC" sweep merge "$TMP/m3" "$TMP/p1" "$TMP/g2" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "a shard of another sweep" "$TMP/o" || fail "merge of two sweeps' shards (rc $rc)"
    "$QC" sweep merge "$TMP/m4" "$TMP/p1" "$TMP/p1" "$TMP/p2" "$TMP/p3" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "appears twice" "$TMP/o" || fail "merge with a shard twice (rc $rc)"
    "$QC" sweep "$HOVER" --shard 4/3 --out "$TMP/x" > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "expected K/N" "$TMP/o" || fail "--shard 4/3 (rc $rc)"
    set -e
    ;;

  keep)  # --keep failing keeps exactly the failing runs' trajectories; they are the runs' own
    # kp 0.5 cannot meet the paper's overshoot band; kp 4 (the paper's) does.
    "$QC" sweep "$ALT" --vary controller.altitude.kp=grid\(4,0.5\) --keep failing --min-pass-rate 0 --no-plots \
      --out "$TMP/f" > /dev/null || fail "keep failing"
    [ ! -e "$TMP/f/runs/0000/trajectory.csv" ] && [ -s "$TMP/f/runs/0001/trajectory.csv" ] || fail "--keep failing kept the wrong runs"
    grep -q '"passed": false' "$TMP/f/runs/0001/metrics.json" && grep -q '"passed": true' "$TMP/f/runs/0000/metrics.json" \
      || fail "run 0 should pass, run 1 fail"
    "$QC" sweep rerun "$TMP/f" 1 --out "$TMP/r1" --no-plots > /dev/null || true
    cmp "$TMP/f/runs/0001/trajectory.csv" "$TMP/r1/trajectory.csv" || fail "kept trajectory differs from the rerun's"
    "$QC" sweep "$ALT" --vary controller.altitude.kp=grid\(4,0.5\) --keep all --min-pass-rate 0 --no-plots --out "$TMP/a" > /dev/null
    [ -s "$TMP/a/runs/0000/trajectory.csv" ] && [ -s "$TMP/a/runs/0001/trajectory.csv" ] || fail "--keep all"
    cmp "$TMP/a/runs/0001/trajectory.csv" "$TMP/r1/trajectory.csv" || fail "--keep all trajectory differs from the rerun's"
    "$QC" sweep "$ALT" --vary controller.altitude.kp=grid\(4,0.5\) --min-pass-rate 0 --no-plots --out "$TMP/n" > /dev/null
    [ -z "$(find "$TMP/n" -name trajectory.csv)" ] || fail "--keep none (the default) kept a trajectory"
    # A key by its YAML path reaches the plant: the first row of the kept trajectory starts at z = 3.
    "$QC" sweep "$HOVER" --vary initial.position_m[2]=grid\(3\) --keep all --min-pass-rate 0 --no-plots --out "$TMP/z" > /dev/null
    "$PY" - "$TMP/z/runs/0000/trajectory.csv" <<'PYEOF' || fail "initial.position_m[2] not flown"
import csv, sys
row = next(csv.DictReader(open(sys.argv[1])))
assert float(row["z"]) == 3.0, row["z"]
PYEOF
    ;;

  hygiene)  # another sweep's outputs: refused without --force; --force removes exactly a sweep's files
    "$QC" sweep "$HOVER" --runs 4 --min-pass-rate 0 --out "$TMP/o1" --no-plots > /dev/null
    touch "$TMP/o1/hist_old.png" "$TMP/o1/notes.txt"
    set +e
    "$QC" sweep "$HOVER" --runs 2 --min-pass-rate 0 --out "$TMP/o1" --no-plots > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "holds another sweep's outputs" "$TMP/o" && grep -q -- "--force" "$TMP/o" || fail "reuse not refused (rc $rc)"
    [ -e "$TMP/o1/runs/0003/metrics.json" ] || fail "the refusal removed files"
    set -e
    "$QC" sweep "$HOVER" --runs 2 --min-pass-rate 0 --out "$TMP/o1" --no-plots --force > /dev/null || fail "--force"
    [ ! -e "$TMP/o1/runs/0003" ] && [ ! -e "$TMP/o1/runs/0002" ] && [ ! -e "$TMP/o1/hist_old.png" ] || fail "stale runs or plots left"
    [ -e "$TMP/o1/notes.txt" ] && [ -e "$TMP/o1/runs/0001/metrics.json" ] || fail "--force removed a file no sweep writes, or the new runs are missing"
    grep -q '"runs": 2' "$TMP/o1/summary.json" || fail "summary.json is not the new sweep's"
    "$QC" run "$HOVER" --out "$TMP/run" --no-plots > /dev/null
    set +e
    "$QC" sweep "$HOVER" --runs 2 --out "$TMP/run" --no-plots --force > "$TMP/o" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "holds a run's outputs" "$TMP/o" || fail "sweep into a run folder (rc $rc)"
    set -e
    ;;

  console)  # every figure with its count and missing runs; a figure no run has says so
    sed 's/duration_s: 15/duration_s: 3/' "$ALT" > "$TMP/short.yaml"
    "$QC" sweep "$TMP/short.yaml" --runs 20 --vary mass=20% --min-pass-rate 0 --no-plots --out "$TMP/c" > "$TMP/log" 2>&1 || fail "sweep"
    "$PY" - "$TMP/c/summary.json" "$TMP/log" <<'PYEOF' || { cat "$TMP/log"; fail "console table"; }
import json, sys
s = json.load(open(sys.argv[1])); log = open(sys.argv[2]).read().splitlines()
assert "count" in log[1] and "missing" in log[1], log[1]
for name, d in s["figures"].items():
    line = next(l for l in log if l.split() and l.split()[0] == name)
    count = sum(r["figures"][name] is not None for r in s["per_run"])
    assert d["count"] == count and d["missing"] == 20 - count, (name, d)
    assert line.split()[1:3] == [str(count), str(20 - count)], line
    if count == 0:
        assert "no run has this figure" in line, line
assert any(d["missing"] > 0 for d in s["figures"].values()), "expected a figure missing in some runs"
PYEOF
    ;;

  *) echo "unknown case $CASE" >&2; exit 2 ;;
esac
