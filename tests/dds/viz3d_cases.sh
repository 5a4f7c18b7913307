#!/usr/bin/env bash
# The vehicle in 3D over DDS: /tf, /tf_static and robot_description from real processes, read with
# quadcosim's own DDS tools and the independent MCAP reader (tools/mcap_verify, npm).
# Usage: viz3d_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
paper="$src/scenarios/paper"
verify="$src/tools/mcap_verify"

need_reader() {
  command -v node > /dev/null || { echo "SKIPPED: node not found (the MCAP reader runs on Node.js)"; exit 77; }
  bash "$verify/install.sh" > "$tmp/npm.log" 2>&1 || { echo "SKIPPED: npm ci failed: $(tail -3 "$tmp/npm.log")"; exit 77; }
}

case "$case_name" in
  tf_lockstep)  # run --transport dds: run.mcap's /tf equals trajectory.csv bit for bit, with the URDF and scene
    need_reader
    "$bin" run "$paper/pitch_step.yaml" --out "$tmp/dds" --no-plots --transport dds > "$tmp/dds.log" 2>&1 \
      || fail "DDS run failed"
    node "$verify/dump.mjs" "$tmp/dds/run.mcap" /tf /tf_static /drone/robot_description /drone/scene \
      > "$tmp/dump.json" || fail "MCAP reader failed"
    /usr/bin/python3 "$src/tests/lib/check_viz3d.py" "$tmp/dump.json" "$tmp/dds/trajectory.csv" /drone 0.59 \
      || fail "3D topics of the DDS run"
    ;;

  late_description)  # a reader that joins after the plant published gets the URDF (transient local)
    "$bin" plant --realtime --duration 20 > "$tmp/plant.log" 2>&1 &
    pids+=($!)
    # The description goes out at tick 0; wait until the plant is seen, then some more.
    "$bin" topic list --wait 5 > "$tmp/list.log" 2>&1 || fail "topic list failed"
    grep -qx "/drone/robot_description" "$tmp/list.log" || fail "no /drone/robot_description in the graph"
    grep -qx "/tf" "$tmp/list.log" || fail "no /tf in the graph"
    sleep 2
    timeout 20 "$bin" topic echo /drone/robot_description --count 1 > "$tmp/urdf.log" 2>&1 \
      || fail "late reader got no robot_description"
    grep -q '<robot name=' "$tmp/urdf.log" || fail "robot_description is not a URDF: $(head -c 300 "$tmp/urdf.log")"
    [ "$(grep -o 'drone/rotor_[1-4]' "$tmp/urdf.log" | sort -u | wc -l)" -eq 4 ] || fail "URDF without 4 rotor links"
    timeout 20 "$bin" topic echo /tf_static --count 1 > "$tmp/static.log" 2>&1 || fail "late reader got no /tf_static"
    [ "$(grep -c 'child_frame_id: drone/rotor_' "$tmp/static.log")" -eq 4 ] || fail "/tf_static without 4 rotors"
    timeout 20 "$bin" topic echo /tf --count 2 > "$tmp/tf.log" 2>&1 || fail "no /tf"
    [ "$(grep -c 'child_frame_id: drone/base_link' "$tmp/tf.log")" -eq 2 ] || fail "/tf without drone/base_link"
    grep -q 'frame_id: world' "$tmp/tf.log" || fail "/tf parent is not world"
    # The control: a volatile reader joining late gets nothing of the description.
    set +e
    timeout 4 "$bin" topic echo /drone/robot_description --count 1 --qos sensor > "$tmp/volatile.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 124 ] || fail "a volatile late reader ended with $rc (expected to wait in vain: timeout 124)"
    grep -q '<robot' "$tmp/volatile.log" && fail "a volatile late reader got the description"
    echo "ok: late transient-local readers get the URDF and /tf_static; a volatile one does not"
    ;;

  swarm_tf)  # a DDS swarm of 3: one /tf transform per vehicle and tick, each its own child frame
    need_reader
    "$bin" record --out "$tmp/bag/tf.mcap" --topics /tf > "$tmp/rec.log" 2>&1 &
    rec=$!; pids+=("$rec")
    sleep 2
    "$bin" run "$src/scenarios/swarm/grid_takeoff.yaml" --vehicles 3 --transport dds --out "$tmp/swarm" \
      --no-plots > "$tmp/swarm.log" 2>&1 || fail "swarm run failed"
    sleep 2
    kill -INT "$rec"
    wait "$rec" || fail "record failed"
    node "$verify/dump.mjs" "$tmp/bag/tf.mcap" /tf > "$tmp/dump.json" || fail "MCAP reader failed"
    /usr/bin/python3 - "$tmp/dump.json" "$tmp/swarm/uav0000/trajectory.csv" <<'PY' || fail "swarm /tf"
import csv, json, sys
msgs = json.load(open(sys.argv[1]))["/tf"]["messages"]
rows = {round(float(r["t"]) * 1e9): r for r in csv.DictReader(open(sys.argv[2]))}
by_frame = {}
for m in msgs:
    ts = m["message"]["transforms"]
    assert len(ts) == 1, ts
    t = ts[0]
    assert t["header"]["frame_id"] == "world", t["header"]
    stamp = t["header"]["stamp"]["sec"] * 10**9 + t["header"]["stamp"]["nanosec"]
    by_frame.setdefault(t["child_frame_id"], []).append((stamp, t["transform"]))
frames = sorted(by_frame)
assert frames == ["uav0000/base_link", "uav0001/base_link", "uav0002/base_link"], frames
ticks = len(rows)
for f, seq in by_frame.items():
    stamps = [s for s, _ in seq]
    assert stamps == sorted(set(stamps)), f + ": stamps repeat or go back"
    # From when the recorder matched the plant's writers. A lockstep swarm outruns a recorder on a busy
    # host: /tf's KEEP_LAST 100 (tf2's) may then drop transforms in its reader, as for any tf2 listener.
    assert all(s % 10_000_000 == 0 and s <= max(rows) for s in stamps), f + ": stamps off the ticks"
    assert len(stamps) >= ticks // 4, (f, len(stamps), ticks)
# Vehicle 0 (recorded) against its trajectory.csv; the others sit on their own grid cells.
for stamp, tr in by_frame["uav0000/base_link"]:
    r = rows[stamp]
    got = [tr["translation"][k] for k in "xyz"] + [tr["rotation"][k] for k in "xyzw"]
    want = [float(r[c]) for c in ("x", "y", "z", "qx", "qy", "qz", "qw")]
    assert got == want, (stamp, got, want)
x1 = by_frame["uav0001/base_link"][-1][1]["translation"]
assert abs(x1["x"] - 2.0) < 0.1 and abs(x1["y"]) < 0.1, x1  # the second cell of a 2 m grid
print("ok: %s, %d transforms each from %d ticks; uav0000 equals its trajectory.csv"
      % (", ".join(frames), len(by_frame[frames[0]]), ticks))
PY
    ;;

  *) fail "unknown case" ;;
esac
