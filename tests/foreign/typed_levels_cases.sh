#!/usr/bin/env bash
# The typed command topics (/drone/cmd/<level>, docs/ros2.md "Commands at every level") from a foreign
# ROS 2 participant (foreign_levels: its own IDL, the plain Cyclone C API, nothing of quadcosim) to
# `quadcosim plant` in lockstep.
# Usage: typed_levels_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FOREIGN_LEVELS TYPED_LEVELS_REFERENCE
#
#   typed_ctbr_identical, typed_velocity_identical: an altitude step (ground to 2 m, 4 s) flown by a law
#     on ThrustRates (VelocityYaw); the plant's recorded states, every tick, bit for bit those of the
#     same law at the same level flown in-process (typed_levels_reference: sim::Simulation, the level
#     named in the command's layout on motor_commands).
#   typed_realtime: the ctbr law against `quadcosim plant --realtime` (4 s of wall time; the stamps are
#     not read): nothing refused, and the climb to 2 m flown (the answers come a little late and the first
#     ones before discovery are lost, so within 0.3 m of 2 m at the end, not bit for bit).
#   typed_rejections: a NaN, a RotorThrusts of 3 values, a tick commanded on two topics (t = 0, 0.02,
#     0.04 s) and a ThrustAttitude with a quaternion of norm 0.5 (t = 1 s): refused, each counted once in
#     plant_status under its own counter and named in last_problem; the run goes on and climbs.
bin="$1"; src="$2"; foreign="$5"; reference="$6"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"

cat > "$tmp/climb.yaml" <<'EOF'
name: typed_levels_climb
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 4}
initial: {position_m: [0, 0, 0]}
EOF

# fly MODE: the plant (lockstep, recording) driven by foreign_levels MODE; leaves $tmp/plant.csv and
# $tmp/foreign.json.
fly() {
  mkdir -p "$tmp/bag"
  "$bin" plant --scenario "$tmp/climb.yaml" --timeout 20 --record "$tmp/plant.csv" --mcap "$tmp/bag/run.mcap" \
    > "$tmp/plant.log" 2>&1 &
  local plant_pid=$!
  pids+=("$plant_pid")
  "$foreign" "$1" 4 > "$tmp/foreign.json" 2> "$tmp/foreign.log" &
  local foreign_pid=$!
  pids+=("$foreign_pid")
  local rc=0
  wait "$plant_pid" || rc=$?
  [ "$rc" -eq 0 ] || fail "plant exited $rc"
  rc=0
  wait "$foreign_pid" || rc=$?
  [ "$rc" -eq 0 ] || fail "foreign_levels exited $rc"
}

# same_states LEVEL: the plant's recorded states equal the in-process reference's, bit for bit.
same_states() {
  "$reference" "$tmp/climb.yaml" "$1" "$tmp/reference.csv" > "$tmp/reference.log" 2>&1 || fail "reference failed"
  /usr/bin/python3 - "$tmp/plant.csv" "$tmp/reference.csv" <<'PY' || fail "states differ from in-process"
import csv, sys
dds = list(csv.DictReader(open(sys.argv[1])))
ref = list(csv.DictReader(open(sys.argv[2])))
assert len(dds) == len(ref) == 401, (len(dds), len(ref))
columns = ref[0].keys()
for a, b in zip(dds, ref):
    for c in columns:
        # Shortest round-trip decimals on both sides: equal floats are equal bits.
        assert float(a[c]) == float(b[c]), f"t = {b['t']} s: {c} {a[c]} over DDS, {b[c]} in-process"
z = [float(r["z"]) for r in ref]
assert z[0] == 0.0 and 1.9 < z[-1] < 2.1 and max(z) > 1.5, (z[0], z[-1], max(z))
print(f"{len(ref)} ticks, {len(columns)} columns identical; z {z[0]} -> {z[-1]:.4f} m")
PY
  grep -q "rejected 0, clamped 0, stale 0;" "$tmp/plant.log" || fail "commands refused: $(grep 'plant: done' "$tmp/plant.log")"
}

case "$case_name" in
  typed_ctbr_identical)
    fly fly-ctbr
    same_states ctbr
    # run.mcap records the typed topic: one ThrustRates per control tick (t = 0 .. 4 s).
    /usr/bin/python3 - "$tmp/bag/metadata.yaml" <<'PY' || fail "run.mcap does not hold the typed commands"
import sys, yaml
meta = yaml.safe_load(open(sys.argv[1]))["rosbag2_bagfile_information"]
topics = {t["topic_metadata"]["name"]: t for t in meta["topics_with_message_count"]}
ctbr = topics["/drone/cmd/ctbr"]
assert ctbr["topic_metadata"]["type"] == "quadcosim_msgs/msg/ThrustRates", ctbr
assert ctbr["message_count"] == 201, ctbr
assert "/drone/cmd/velocity" not in topics, sorted(topics)
print(f"run.mcap: {ctbr['message_count']} messages on /drone/cmd/ctbr")
PY
    ;;
  typed_velocity_identical)
    fly fly-velocity
    same_states velocity
    ;;
  typed_rejections)
    fly reject
    /usr/bin/python3 - "$tmp/foreign.json" "$tmp/plant.csv" <<'PY' || fail "rejections not as expected"
import csv, json, sys
j = json.load(open(sys.argv[1]))
s = j["status"]
want = {"rejected_non_finite": 1, "rejected_length": 1, "rejected_second_topic": 1, "rejected_bad_quaternion": 1,
        "stale": 0}
for k, v in want.items():
    assert s[k] == v, f"plant_status {k} = {s[k]}, expected {v}: {s}"
# Every answer but the three bad ones, and but the last: the status of the last tick went out with its
# samples, before that tick's answer.
assert s["accepted"] == j["answered"] - 3 - 1, (s["accepted"], j["answered"])
problems = s["problems"]
for p in ("ctbr value 1 (thrust [N]) is nan, expected a finite number",
          "3 values, expected 4 for level rotor_thrusts",
          "a command on /drone/cmd/velocity for the tick (t = 0.04 s) that /drone/cmd/ctbr already commanded: one "
          "topic commands a tick",
          "ctatt attitude has norm 0.5, expected a unit quaternion (x, y, z, w)"):
    assert p in problems, f"last_problem never said '{p}': {problems}"
z = [float(r["z"]) for r in csv.DictReader(open(sys.argv[2]))]
assert z[4] == 0.0 and z[-1] > 1.5, (z[4], z[-1])  # no command flown before t = 0.04 s; then the climb
print(f"refused and named: {problems}")
PY
    grep -q "rejected 3, clamped 0, stale 0; foreign (not the controller's writers) 0; on a second topic 1" \
      "$tmp/plant.log" || fail "plant summary: $(grep 'plant: done' "$tmp/plant.log")"
    ;;
  typed_realtime)
    "$bin" plant --realtime --duration 4 --watchdog-policy hold --record "$tmp/plant.csv" > "$tmp/plant.log" 2>&1 &
    plant_pid=$!
    pids+=("$plant_pid")
    "$foreign" fly-ctbr 4 > "$tmp/foreign.json" 2> "$tmp/foreign.log" &
    foreign_pid=$!
    pids+=("$foreign_pid")
    rc=0
    wait "$plant_pid" || rc=$?
    [ "$rc" -eq 0 ] || fail "plant exited $rc"
    rc=0
    wait "$foreign_pid" || rc=$?
    [ "$rc" -eq 0 ] || fail "foreign_levels exited $rc"
    grep -Eq "commands received [1-9][0-9]+, rejected 0, clamped 0, stale 0; foreign \(not the controller's writers\) 0; on a second topic 0" \
      "$tmp/plant.log" || fail "plant summary: $(grep 'plant: done' "$tmp/plant.log")"
    /usr/bin/python3 - "$tmp/plant.csv" <<'PY' || fail "the climb was not flown"
import csv, sys
z = [float(r["z"]) for r in csv.DictReader(open(sys.argv[1]))]
assert abs(z[-1] - 2.0) < 0.3 and max(z) < 3.0, (z[-1], max(z))
print(f"real time: z {z[0]} -> {z[-1]:.3f} m over {len(z)} rows")
PY
    ;;
  *) fail "unknown case $case_name" ;;
esac
echo "PASS [$case_name]"
