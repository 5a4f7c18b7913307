#!/usr/bin/env bash
# Output folders never mix runs (docs/outputs.md, "Output folders"): a used folder is refused (exit 2,
# naming it) unless --force, which removes exactly the files the previous command wrote; `plot` and
# `compare` replace their own previous figures. One case per CTest test.
#   usage: output_folder_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
MANIFEST=.quadcosim-outputs.json

# Short copies of a scenario (fewer rows to plot): altitude (step_z) and position (step_x, step_y).
sed 's/duration_s: 15/duration_s: 4/' "$SRC/scenarios/paper/altitude_step.yaml" > "$TMP/alt.yaml"
sed 's/duration_s: 20/duration_s: 4/' "$SRC/scenarios/examples/position_step.yaml" > "$TMP/pos.yaml"

# Exit code of "$@" (stdout and stderr in $TMP/out, $TMP/err).
rc_of() { set +e; "$@" > "$TMP/out" 2> "$TMP/err"; local rc=$?; set -e; echo $rc; }

# The files the manifest of folder $1 lists, one per line, sorted.
listed() { "$PY" -c 'import json,sys; m=json.load(open(sys.argv[1])); print("\n".join(sorted(f for g in m["files"].values() for f in g)))' "$1/$MANIFEST"; }

case "$CASE" in
  run_reuse)  # another scenario into a used run folder: refused; --force leaves none of the first run's files
    rc=$(rc_of "$QC" run "$TMP/pos.yaml" --out "$TMP/d")
    [ "$rc" -le 1 ] || { cat "$TMP/err"; fail "first run: exit $rc"; }
    [ -s "$TMP/d/step_x.png" ] && [ -s "$TMP/d/report.html" ] || fail "the first run wrote no step_x.png or report"
    # The manifest lists exactly the files in the folder.
    [ "$(listed "$TMP/d")" = "$(cd "$TMP/d" && find . -type f ! -name $MANIFEST | sed 's|^\./||' | sort)" ] \
      || fail "manifest and folder differ: $(listed "$TMP/d")"
    echo mine > "$TMP/d/notes.txt"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d")
    [ "$rc" = 2 ] || fail "reuse without --force: exit $rc"
    grep -q "$TMP/d is not empty: it holds the outputs of \`quadcosim run\`" "$TMP/err" && grep -q notes.txt "$TMP/err" \
      && grep -q -- "--force" "$TMP/err" || fail "the refusal does not say what the folder holds: $(cat "$TMP/err")"
    [ -s "$TMP/d/step_x.png" ] || fail "the refusal removed files"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --force)
    [ "$rc" -le 1 ] || { cat "$TMP/err"; fail "--force: exit $rc"; }
    for f in step_x.png step_y.png; do [ ! -e "$TMP/d/$f" ] || fail "$f of the first run is left"; done
    [ -s "$TMP/d/step_z.png" ] || fail "no step_z.png"
    [ "$(cat "$TMP/d/notes.txt")" = mine ] || fail "the user's notes.txt was not kept"
    grep -q "kept 1 file quadcosim did not write: notes.txt" "$TMP/err" || fail "the kept file is not named"
    grep -q "step_x" "$TMP/d/report.html" && fail "report.html names the first run's figure"
    listed "$TMP/d" | grep -qx notes.txt && fail "notes.txt is listed as a quadcosim output"
    grep -q '"command": "run"' "$TMP/d/$MANIFEST" || fail "manifest does not name the command"
    ;;

  run_dds)  # the same over DDS: refused without --force, and --force replaces an in-process run's files
    "$QC" run "$TMP/pos.yaml" --out "$TMP/d" --no-plots > /dev/null 2>&1 || true
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots --transport dds)
    [ "$rc" = 2 ] && grep -q "$TMP/d is not empty" "$TMP/err" || fail "dds into a used folder: exit $rc: $(cat "$TMP/err")"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots --transport dds --force)
    [ "$rc" -le 1 ] || { cat "$TMP/err"; fail "dds --force: exit $rc"; }
    "$QC" run "$TMP/alt.yaml" --out "$TMP/in" --no-plots > /dev/null || true
    cmp "$TMP/in/trajectory.csv" "$TMP/d/trajectory.csv" || fail "the dds run differs from the in-process one"
    [ "$(listed "$TMP/d")" = "$(listed "$TMP/in")" ] || fail "dds and in-process runs list other files"
    ;;

  swarm)  # a swarm's folder replaced by one vehicle's run: no vehicles.csv or uav folder left
    "$QC" run "$SRC/scenarios/swarm/grid_takeoff.yaml" --vehicles 4 --out "$TMP/d" --no-plots > /dev/null 2>&1 || true
    [ -s "$TMP/d/vehicles.csv" ] || fail "the swarm wrote no vehicles.csv"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots)
    [ "$rc" = 2 ] || fail "run into a swarm's folder: exit $rc"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots --force)
    [ "$rc" -le 1 ] || { cat "$TMP/err"; fail "--force: exit $rc"; }
    [ "$(cd "$TMP/d" && find . -mindepth 1 ! -name $MANIFEST | sed 's|^\./||' | sort | tr '\n' ' ')" = \
      "metadata.yaml metrics.json metrics.txt run.mcap scenario.yaml trajectory.csv " ] \
      || fail "left after --force: $(ls -A "$TMP/d")"
    ;;

  plot_after_change)  # plot removes the figures a previous plot wrote that the run no longer has
    "$QC" run "$TMP/pos.yaml" --out "$TMP/d" > /dev/null 2>&1 || true
    "$QC" run "$TMP/alt.yaml" --out "$TMP/alt" --no-plots > /dev/null || true
    [ -s "$TMP/d/step_x.png" ] || fail "no step_x.png"
    # The run changes: now an altitude step (its data replaced by hand, as a user might).
    cp "$TMP/alt/trajectory.csv" "$TMP/alt/metrics.json" "$TMP/d/"
    echo mine > "$TMP/d/notes.txt"
    rc=$(rc_of "$QC" plot "$TMP/d")
    [ "$rc" = 0 ] || { cat "$TMP/err"; fail "plot: exit $rc"; }
    [ ! -e "$TMP/d/step_x.png" ] && [ ! -e "$TMP/d/step_y.png" ] || fail "plot left the figures of the old steps"
    [ -s "$TMP/d/step_z.png" ] && [ -s "$TMP/d/report.html" ] || fail "plot wrote no step_z.png or report"
    [ -s "$TMP/d/trajectory.csv" ] && [ -e "$TMP/d/notes.txt" ] || fail "plot removed a file that is no figure"
    [ "$(grep -o 'alt="[a-z_0-9]*\.png"' "$TMP/d/report.html" | tr '\n' ' ')" = 'alt="step_z.png" alt="outputs.png" alt="overview.png" ' ] \
      || fail "report.html lists other figures: $(grep -o 'alt="[^"]*"' "$TMP/d/report.html")"
    "$PY" - "$TMP/d/$MANIFEST" <<'PYEOF' || fail "manifest"
import json, sys
m = json.load(open(sys.argv[1]))
assert m["command"] == "run", m
assert m["files"]["figures"] == ["outputs.png", "overview.png", "report.html", "step_z.png"], m["files"]["figures"]
assert "notes.txt" not in m["files"]["outputs"] and "trajectory.csv" in m["files"]["outputs"], m["files"]["outputs"]
PYEOF
    ;;

  compare)  # compare replaces a previous compare's files; a folder holding anything else needs --force
    "$QC" run "$TMP/pos.yaml" --out "$TMP/pos" --no-plots > /dev/null 2>&1 || true
    "$QC" run "$TMP/alt.yaml" --out "$TMP/alt" --no-plots > /dev/null || true
    rc=$(rc_of "$QC" compare "$TMP/pos" "$TMP/pos" --out "$TMP/c")
    [ "$rc" = 0 ] && [ -s "$TMP/c/compare_x.png" ] || { cat "$TMP/err"; fail "compare: exit $rc"; }
    rc=$(rc_of "$QC" compare "$TMP/alt" "$TMP/alt" --out "$TMP/c")
    [ "$rc" = 0 ] || { cat "$TMP/err"; fail "compare again into its own folder: exit $rc"; }
    [ ! -e "$TMP/c/compare_x.png" ] && [ -s "$TMP/c/compare_z.png" ] || fail "the first comparison's plot is left"
    rc=$(rc_of "$QC" compare "$TMP/alt" "$TMP/alt" --out "$TMP/pos")
    [ "$rc" = 2 ] && grep -q "$TMP/pos is not empty: it holds the outputs of \`quadcosim run\`" "$TMP/err" \
      || fail "compare into a run's folder: exit $rc: $(cat "$TMP/err")"
    [ -s "$TMP/pos/trajectory.csv" ] || fail "the refused compare removed the run's files"
    # The default folder, inside RUN_B, is not the run's: a new run there with --force keeps it.
    rc=$(rc_of "$QC" compare "$TMP/pos" "$TMP/alt")
    [ "$rc" = 0 ] && [ -s "$TMP/alt/compare_with_pos/compare.md" ] || fail "default compare folder: exit $rc"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/alt" --no-plots --force)
    [ "$rc" -le 1 ] && [ -s "$TMP/alt/compare_with_pos/compare.md" ] || fail "run --force removed another command's folder"
    grep -q "kept the outputs of other commands in compare_with_pos/" "$TMP/err" || fail "kept folder not named"
    ;;

  sweep_shrink)  # 12 runs, then 2 with --force: exactly the 2 new runs' files are left
    H="$SRC/scenarios/realism/hover_wind_gusts.yaml"
    "$QC" sweep "$H" --runs 12 --keep all --min-pass-rate 0 --no-plots --out "$TMP/s" > /dev/null
    [ "$(ls "$TMP/s/runs" | wc -l)" = 12 ] || fail "the first sweep has not 12 runs"
    rc=$(rc_of "$QC" sweep "$H" --runs 2 --keep all --min-pass-rate 0 --no-plots --out "$TMP/s")
    [ "$rc" = 2 ] && grep -q "outputs of \`quadcosim sweep\` (27 files" "$TMP/err" || fail "reuse: exit $rc: $(cat "$TMP/err")"
    "$QC" sweep "$H" --runs 2 --keep all --min-pass-rate 0 --no-plots --out "$TMP/s" --force > /dev/null || fail "--force"
    [ "$(cd "$TMP/s" && find . -mindepth 1 ! -name $MANIFEST | sed 's|^\./||' | sort | tr '\n' ' ')" = \
      "origin.json runs runs/0000 runs/0000/metrics.json runs/0000/trajectory.csv runs/0001 runs/0001/metrics.json runs/0001/trajectory.csv scenario.yaml summary.json " ] \
      || fail "left after --force: $(cd "$TMP/s" && find . | sort | tr '\n' ' ')"
    # merge and rerun follow the same rule
    rc=$(rc_of "$QC" sweep rerun "$TMP/s" 1 --out "$TMP/s" --no-plots)
    [ "$rc" = 2 ] && grep -q "$TMP/s is not empty" "$TMP/err" || fail "rerun into the sweep's folder: exit $rc"
    ;;

  disk_full)  # the disk fills during an in-process run: exit 3, the manifest whole (never 0 bytes), --force works after
    # A small tmpfs of its own: only root can mount one; elsewhere SKIPPED (77) with the reason.
    [ "$(id -u)" = 0 ] || { echo "SKIPPED: mounting a small tmpfs needs root"; exit 77; }
    mkdir "$TMP/small"
    mount -t tmpfs -o size=96k tmpfs "$TMP/small" 2> "$TMP/mount.err" \
      || { echo "SKIPPED: cannot mount a tmpfs here: $(cat "$TMP/mount.err")"; exit 77; }
    trap 'umount "$TMP/small" 2> /dev/null || true; rm -rf "$TMP"' EXIT
    # --no-limits: the projected outputs would be refused up front (exit 2, docs/reliability.md); this is
    # a disk that fills during the run, as when something else fills it.
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/small/d" --no-plots --no-limits)
    [ "$rc" = 3 ] && grep -q "No space left on device" "$TMP/err" || { cat "$TMP/err"; fail "a full disk: exit $rc, expected 3"; }
    [ -s "$TMP/small/d/$MANIFEST" ] || fail "the manifest is empty or missing after the disk filled"
    "$PY" -c 'import json,sys; assert json.load(open(sys.argv[1]))["command"] == "run"' "$TMP/small/d/$MANIFEST" \
      || fail "the manifest is not whole: $(cat "$TMP/small/d/$MANIFEST")"
    ls -a "$TMP/small/d" | grep -q '\.tmp-' && fail "a temporary file was left: $(ls -a "$TMP/small/d")"
    # With room again, --force takes the folder (the manifest is read, not refused).
    mount -o remount,size=64m "$TMP/small"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/small/d" --no-plots --force)
    [ "$rc" -le 1 ] || { cat "$TMP/err"; fail "--force after the disk filled: exit $rc"; }
    [ -s "$TMP/small/d/metrics.json" ] || fail "no metrics.json after --force"
    umount "$TMP/small"
    ;;

  symlink)  # `run --force` never writes through a link planted in its folder
    echo precious > "$TMP/victim"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots)
    [ "$rc" -le 1 ] || fail "first run: exit $rc"
    rm "$TMP/d/metrics.json" && ln -s "$TMP/victim" "$TMP/d/metrics.json"
    rc=$(rc_of "$QC" run "$TMP/alt.yaml" --out "$TMP/d" --no-plots --force)
    [ "$rc" = 2 ] && grep -q "metrics.json: symbolic links" "$TMP/err" || { cat "$TMP/err"; fail "planted link: exit $rc"; }
    [ "$(cat "$TMP/victim")" = precious ] || fail "the link's target was written"
    [ -L "$TMP/d/metrics.json" ] || fail "the refusal removed the link"
    ;;

  *) fail "unknown case" ;;
esac
echo "ok [$CASE]"
