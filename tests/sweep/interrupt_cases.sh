#!/usr/bin/env bash
# A sweep survives Ctrl-C (SIGINT) and SIGTERM (docs/sweeps.md, "Interrupting and resuming"): it
# exits 130 having written the summary of its finished runs (marked partial) and a manifest listing
# every file it wrote; `--resume` runs only the missing runs, and the final summary.json (or
# shard.json) are the bytes of an uninterrupted sweep's, and every run's metrics.json its judgement
# (the same JSON besides the provenance, which names the command line: --resume). `--force` after
# an interruption leaves none of the interrupted sweep's runs. Every process the script starts is
# killed by PID on exit, also on failure (tests/lib/process_case.sh). One case per CTest test.
#   usage: interrupt_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE DOMAIN_ID
QC=$1
SRC=$2
# shellcheck source=../lib/process_case.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "sweep.$3" "$4"
CASE=$3
PY=${QUADCOSIM_PYTHON:-/usr/bin/python3}
HOVER="$SRC/scenarios/realism/hover_wind_gusts.yaml"

# same_runs REF_RUNS RUNS: the same run files, each metrics.json with the same judgement.
same_runs() {
  [ "$(cd "$1" && find . -type f | sort)" = "$(cd "$2" && find . -type f | sort)" ] || return 1
  local f
  for f in "$1"/*/metrics.json; do
    "$PY" "$SRC/tests/lib/same_metrics.py" "$f" "$2/${f#"$1/"}" || return 1
  done
}
RUNS=100
A=(--runs $RUNS --vary mass=10% --vary controller.altitude.kd=uniform\(2,3.5\) --min-pass-rate 0 --no-plots)

# Starts the sweep of $SCENARIO (default $HOVER) with "$@" in the background (log in $tmp/bg.log),
# waits until run $WAIT_RUN's metrics.json exists in $OUT, sends $SIGNAL and sets rc to the exit code.
interrupt() {
  "$QC" sweep "${SCENARIO:-$HOVER}" "$@" > "$tmp/bg.log" 2>&1 &
  local pid=$!
  pids+=("$pid")
  for _ in $(seq 600); do
    [ -e "$OUT/runs/$WAIT_RUN/metrics.json" ] && break
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.05
  done
  kill "-$SIGNAL" "$pid" 2> /dev/null || fail "the sweep ended before it could be interrupted: $(cat "$tmp/bg.log")"
  set +e
  wait "$pid"
  rc=$?
  set -e
}

# The files the manifest of folder $1 lists against the files in it (both sorted), or fail.
manifest_is_folder() {
  local listed present
  listed=$("$PY" -c 'import json,sys; m=json.load(open(sys.argv[1])); print("\n".join(sorted(f for g in m["files"].values() for f in g)))' "$1/.quadcosim-outputs.json")
  present=$(cd "$1" && find . -type f ! -name .quadcosim-outputs.json | sed 's|^\./||' | sort)
  [ "$listed" = "$present" ] || fail "manifest of $1 differs from its files: listed $(echo "$listed" | wc -l), present $(echo "$present" | wc -l)"
}

case "$CASE" in
  interrupt_resume)  # SIGINT mid-way: exit 130, a partial summary; --resume gives the uninterrupted bytes
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --jobs 2 --out "$tmp/ref" > "$tmp/ref.log" 2>&1 || fail "uninterrupted sweep"
    OUT="$tmp/s" WAIT_RUN=0004 SIGNAL=INT interrupt "${A[@]}" --seed 11 --jobs 2 --out "$tmp/s"
    [ "$rc" -eq 130 ] || fail "SIGINT: exit $rc, expected 130: $(cat "$tmp/bg.log")"
    grep -q "interrupted: [0-9]* of $RUNS runs finished" "$tmp/bg.log" && grep -q -- "--resume" "$tmp/bg.log" \
      || fail "no word of the interruption and of --resume: $(cat "$tmp/bg.log")"
    manifest_is_folder "$tmp/s"
    "$PY" - "$tmp/s" "$tmp/ref/summary.json" $RUNS <<'PYEOF' || fail "partial summary"
import json, os, sys
d, ref, runs = sys.argv[1], json.load(open(sys.argv[2])), int(sys.argv[3])
s = json.load(open(os.path.join(d, "summary.json")))
f = s["partial"]["finished"]
assert s["partial"]["runs"] == runs and 5 <= f < runs, s["partial"]
idx = [r["index"] for r in s["per_run"]]
on_disk = sorted(int(n) for n in os.listdir(os.path.join(d, "runs")))
assert idx == on_disk and len(idx) == f, (idx, on_disk)
# The finished runs are the uninterrupted sweep's runs, number for number.
assert s["per_run"] == [ref["per_run"][i] for i in idx]
assert s["passed"] == sum(r["passed"] for r in s["per_run"])
for name, c in s["figures"].items():
    assert c["count"] + c["missing"] == f, (name, c)
print(f"partial: {f} of {runs}")
PYEOF
    # --resume with other options is refused, and so is --resume with --force.
    set +e
    "$QC" sweep "$HOVER" "${A[@]}" --seed 12 --resume --out "$tmp/s" > "$tmp/o.log" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "seed differs" "$tmp/o.log" || fail "--resume with another seed (rc $rc): $(cat "$tmp/o.log")"
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --resume --force --out "$tmp/s" > "$tmp/o.log" 2>&1; rc=$?
    [ $rc -eq 2 ] || fail "--resume --force (rc $rc)"
    set -e
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --jobs 2 --resume --out "$tmp/s" > "$tmp/resume.log" 2>&1 \
      || fail "--resume: $(cat "$tmp/resume.log")"
    grep -q "resuming in $tmp/s: [0-9]* runs finished, [0-9]* to run" "$tmp/resume.log" || fail "resume message"
    cmp "$tmp/ref/summary.json" "$tmp/s/summary.json" || fail "the resumed summary.json differs from the uninterrupted one"
    same_runs "$tmp/ref/runs" "$tmp/s/runs" || fail "the resumed runs' metrics.json differ"
    cmp "$tmp/ref/.quadcosim-outputs.json" "$tmp/s/.quadcosim-outputs.json" || fail "the manifests differ"
    # Resuming a finished sweep: nothing to do.
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --resume --out "$tmp/s" > "$tmp/o.log" 2>&1 || fail "--resume of a finished sweep"
    grep -q "nothing to resume" "$tmp/o.log" || fail "no 'nothing to resume'"
    ;;

  sigterm_shard)  # a shard stopped by SIGTERM: merge refuses it; --resume gives the uninterrupted shard.json
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --shard 1/2 --jobs 1 --out "$tmp/ref" > "$tmp/ref.log" 2>&1 || fail "uninterrupted shard"
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --shard 2/2 --out "$tmp/p2" > /dev/null 2>&1 || fail "shard 2"
    OUT="$tmp/p1" WAIT_RUN=0006 SIGNAL=TERM interrupt "${A[@]}" --seed 11 --shard 1/2 --jobs 1 --out "$tmp/p1"
    [ "$rc" -eq 130 ] || fail "SIGTERM: exit $rc, expected 130: $(cat "$tmp/bg.log")"
    "$PY" -c 'import json,sys; j=json.load(open(sys.argv[1])); p=j["partial"]; assert p["runs"] == 50 and 4 <= p["finished"] < 50, p' \
      "$tmp/p1/shard.json" || fail "partial shard.json"
    manifest_is_folder "$tmp/p1"
    set +e
    "$QC" sweep merge "$tmp/m" "$tmp/p1" "$tmp/p2" --no-plots > "$tmp/o.log" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "was interrupted" "$tmp/o.log" || fail "merge of an interrupted shard (rc $rc): $(cat "$tmp/o.log")"
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --shard 2/2 --resume --out "$tmp/p1" > "$tmp/o.log" 2>&1; rc=$?
    [ $rc -eq 2 ] && grep -q "shard 1/2, not shard 2/2" "$tmp/o.log" || fail "--resume as another shard (rc $rc): $(cat "$tmp/o.log")"
    set -e
    "$QC" sweep "$HOVER" "${A[@]}" --seed 11 --shard 1/2 --jobs 2 --resume --out "$tmp/p1" > "$tmp/o.log" 2>&1 || fail "--resume"
    cmp "$tmp/ref/shard.json" "$tmp/p1/shard.json" || fail "the resumed shard.json differs from the uninterrupted one"
    same_runs "$tmp/ref/runs" "$tmp/p1/runs" || fail "the resumed shard's runs differ"
    "$QC" sweep merge "$tmp/m" "$tmp/p1" "$tmp/p2" --no-plots --min-pass-rate 0 > /dev/null || fail "merge"
    ;;

  force_after_interrupt)  # --force after an interrupted sweep: no run of the old sweep is left
    OUT="$tmp/s" WAIT_RUN=0004 SIGNAL=TERM interrupt "${A[@]}" --seed 11 --jobs 2 --out "$tmp/s"
    [ "$rc" -eq 130 ] || fail "SIGTERM: exit $rc"
    "$QC" sweep "$HOVER" --runs 3 --seed 2 --min-pass-rate 0 --no-plots --force --out "$tmp/s" > "$tmp/o.log" 2>&1 \
      || fail "--force: $(cat "$tmp/o.log")"
    [ "$(ls "$tmp/s/runs" | tr '\n' ' ')" = "0000 0001 0002 " ] || fail "runs left: $(ls "$tmp/s/runs" | head)"
    for m in "$tmp"/s/runs/*/metrics.json; do
      "$PY" -c 'import json,sys; assert json.load(open(sys.argv[1]))["sweep"]["sweep_seed"] == 2' "$m" || fail "$m is the old sweep's"
    done
    manifest_is_folder "$tmp/s"
    # A folder an older quadcosim left (runs on disk its manifest does not list): refused, kept.
    "$PY" -c 'import json,sys; json.dump({"command": "sweep", "files": {}}, open(sys.argv[1], "w"))' "$tmp/s/.quadcosim-outputs.json"
    set +e
    "$QC" sweep "$HOVER" --runs 2 --min-pass-rate 0 --no-plots --force --out "$tmp/s" > "$tmp/o.log" 2>&1; rc=$?
    set -e
    [ $rc -eq 2 ] && grep -q "runs/ holds 3 files that no manifest lists" "$tmp/o.log" \
      || fail "unlisted runs not refused (rc $rc): $(cat "$tmp/o.log")"
    [ -e "$tmp/s/runs/0002/metrics.json" ] || fail "the refusal removed a file"
    ;;

  resume_elsewhere)  # --resume and `sweep rerun` from another folder find the Python controller the sweep flew
    if "$QC" controller --python "no_such_module_for_the_check:X" > "$tmp/check.log" 2>&1; then :; fi
    if grep -q "built without Python" "$tmp/check.log"; then
      echo "SKIP: this quadcosim was built without Python: $(cat "$tmp/check.log")"
      exit 77
    fi
    # The scenario's folder holds altitude_pd.py (tests/python_node); the folder the sweep starts in
    # holds start_pd.py, the class the scenario names, which imports altitude_pd: the first is found
    # from the scenario's folder, the second only from the starting folder (the current directory).
    mkdir -p "$tmp/scn" "$tmp/start" "$tmp/other"
    cp "$SRC/tests/python_node/altitude_pd.py" "$tmp/scn/"
    printf 'from altitude_pd import AltitudePD as StartPD  # noqa: F401\n' > "$tmp/start/start_pd.py"
    cat > "$tmp/scn/pd.yaml" <<'YAML'
name: python_pd
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 3}
initial: {position_m: [0, 0, 0]}
controller:
  python: "start_pd:StartPD"
  mode: attitude
  z_des: 0
schedule:
  - at_s: 0
    set: {z_des: 1.0}
analysis:
  steps:
    - channel: z
      at_s: 0
      criteria:
        overshoot_pct: [null, 30]
YAML
    P=(--runs 24 --vary mass=10% --seed 4 --min-pass-rate 0 --no-plots --no-progress)
    (cd "$tmp/start" && "$QC" sweep ../scn/pd.yaml "${P[@]}" --jobs 2 --out ../ref > "$tmp/ref.log" 2>&1) \
      || fail "uninterrupted sweep: $(cat "$tmp/ref.log")"
    "$PY" -c 'import json,sys; o=json.load(open(sys.argv[1])); assert o["python_path"][:2] == [sys.argv[2], sys.argv[3]], o' \
      "$tmp/ref/origin.json" "$tmp/scn" "$tmp/start" || fail "origin.json: $(cat "$tmp/ref/origin.json")"
    cd "$tmp/start"
    SCENARIO=../scn/pd.yaml OUT="$tmp/s" WAIT_RUN=0003 SIGNAL=INT interrupt "${P[@]}" --jobs 1 --out ../s
    [ "$rc" -eq 130 ] || fail "SIGINT: exit $rc, expected 130: $(cat "$tmp/bg.log")"
    cd "$tmp/other"
    # From elsewhere, the scenario given by another path: the recorded folders are imported from.
    "$QC" sweep "$tmp/scn/pd.yaml" "${P[@]}" --jobs 2 --resume --out ../s > "$tmp/resume.log" 2>&1 \
      || fail "--resume from another folder: $(cat "$tmp/resume.log")"
    grep -q "resuming in ../s: [0-9]* runs finished" "$tmp/resume.log" || fail "resume message: $(cat "$tmp/resume.log")"
    cmp "$tmp/ref/summary.json" "$tmp/s/summary.json" || fail "the resumed summary.json differs from the uninterrupted one"
    # Their provenance names the command lines (--resume, another folder): the same judgement.
    same_runs "$tmp/ref/runs" "$tmp/s/runs" || fail "the resumed runs' metrics.json differ"
    "$QC" sweep rerun ../s 5 --out ../r5 --no-plots > "$tmp/rerun.log" 2>&1 || [ $? -eq 1 ] \
      || fail "rerun from another folder: $(cat "$tmp/rerun.log")"
    "$PY" - "$tmp/s/summary.json" "$tmp/r5/metrics.json" <<'PYEOF' || fail "the rerun differs from the sweep's run"
import json, sys
s, m = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
run = s["per_run"][5]
figs = {"z." + n: v for n, v in m["steps"][0]["figures"].items()}
figs.update({"saturation." + n: v for n, v in m["saturation"]["figures"].items()})
assert figs == run["figures"] and m["passed"] == run["passed"], (figs, run)
PYEOF
    # Without the record, the starting folder's module is not found from here: what made it work.
    mkdir "$tmp/bare"
    cp "$tmp/s/summary.json" "$tmp/s/scenario.yaml" "$tmp/bare/"
    set +e
    "$QC" sweep rerun ../bare 5 --out ../r5b --no-plots > "$tmp/bare.log" 2>&1; rc=$?
    set -e
    [ $rc -eq 2 ] && grep -q "start_pd" "$tmp/bare.log" || fail "rerun without origin.json (rc $rc): $(cat "$tmp/bare.log")"
    ;;

  *) fail "unknown case $CASE" ;;
esac
echo "ok: $CASE"
