#!/usr/bin/env bash
# A foreign ROS 2 participant (foreign_controller: own IDL, plain Cyclone C API, nothing of quadcosim)
# drives `quadcosim plant --realtime`. Usage: foreign_test.sh BIN_QUADCOSIM BIN_FOREIGN DOMAIN_ID
#
# Runs on ROS_DOMAIN_ID=DOMAIN_ID with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, ends every process it
# started (trap), also on failure, and then checks what the foreign node received (its JSON line) and
# what the plant did with the foreign node's commands (the plant's CSV).
#
# Bounds (plant at 100 Hz for 6 s of wall time = ticks 0..600; foreign node for 5 s, started right after):
#  - Pose/Velocity/Imu: 100 Hz over ~5 s is ~450-500 samples once discovery (well under 1 s on
#    localhost) is done; >= 250 leaves 2.5 s for discovery and scheduling on a loaded 2-core machine
#    and still requires a sustained, reliable stream. <= 601: the plant publishes only 601 ticks.
#  - clock: best effort with depth 1 on our side (rclcpp's ClockQoS), so samples may legitimately be
#    overwritten before we take them: >= 100, <= 601.
#  - z: the foreign PD (kp = 4 N/m, kd = 2.7 N s/m, m = 1.96 kg, ideal motors, gravity fed forward)
#    makes z'' = (kp (2 - z) - kd z')/m: wn = 1.43 rad/s, zeta = 0.48, overshoot 18 % (peak 2.36 m at
#    2.5 s), |z - 2| < 0.08 m after 4 s. At >= 2.5 s of driving (the count bound) the last thrust
#    error is <= 0.74 m/s^2 of specific force, and after the foreign node stops the plant holds its
#    last command (watchdog policy hold): simulating drive windows from 2 to 5.4 s with the rest held gives z(6 s) in
#    [1.5, 2.13] m. Hence: final z in [1.0, 3.0], the highest z <= 3.0 (peak 2.36), and z is 0 up to
#    the first applied foreign command (on the ground, rotors stopped: nobody else commands them).
#  - Imu linear_acceleration.z at the last sample = thrust/m (level attitude, equal rotors):
#    9.81 +- 0.74 after >= 2.5 s of PD flight; we accept 9.81 +- 1.0.
set -euo pipefail
bin="$1"; foreign="$2"
export ROS_DOMAIN_ID="$3" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
tmp="$(mktemp -d)"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  sleep 0.2
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() {
  echo "FAIL [foreign.drives_plant]: $*"
  for f in "$tmp"/plant.log "$tmp"/foreign.log "$tmp"/foreign.json; do
    [ -f "$f" ] && { echo "--- $f"; tail -20 "$f"; }
  done
  exit 1
}
# wait_for PID SECONDS: the exit status of PID; TERM (then KILL) if it outlives SECONDS.
wait_for() {
  local pid="$1" limit="$2" i
  for ((i = 0; i < limit * 10; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    sleep 1
    kill -KILL "$pid" 2>/dev/null || true
  fi
  local rc=0
  wait "$pid" || rc=$?
  return "$rc"
}

# --watchdog-policy hold: the plant keeps the foreign node's last command after it stops (the
# default watchdog would stop the motors 0.5 s later; docs/reliability.md).
"$bin" plant --realtime --duration 6 --watchdog-policy hold --record "$tmp/plant.csv" > "$tmp/plant.log" 2>&1 &
plant_pid=$!; pids+=("$plant_pid")
"$foreign" 5 > "$tmp/foreign.json" 2> "$tmp/foreign.log" &
foreign_pid=$!; pids+=("$foreign_pid")

set +e
wait_for "$foreign_pid" 30; foreign_rc=$?
wait_for "$plant_pid" 60; plant_rc=$?
set -e
[ "$foreign_rc" -eq 0 ] || fail "foreign controller exited $foreign_rc"
[ "$plant_rc" -eq 0 ] || fail "plant exited $plant_rc"
[ -s "$tmp/foreign.json" ] || fail "foreign controller printed no JSON"
[ -s "$tmp/plant.csv" ] || fail "plant wrote no CSV"
grep -q "rejected 0," "$tmp/plant.log" || fail "the plant rejected foreign commands"

python3 - "$tmp/foreign.json" "$tmp/plant.csv" <<'EOF' || fail "assertions failed"
import csv, json, math, sys

errors = []
def check(ok, what):
    if not ok:
        errors.append(what)

seen = json.loads(open(sys.argv[1]).readline())
print("foreign:", json.dumps(seen))
c = seen["counts"]
for topic in ("pose", "velocity", "imu"):
    check(250 <= c[topic] <= 601, f"{topic}: {c[topic]} samples, expected 250..601")
check(100 <= c["clock"] <= 601, f"clock: {c['clock']} samples, expected 100..601")
for topic, n in seen["stamp_errors"].items():
    check(n == 0, f"{topic}: {n} stamps not increasing or nanosec >= 1e9 (Time_ layout)")
f = seen["frame_ids"]
check(f["pose"] == "world", f"Pose frame_id {f['pose']!r}, expected 'world'")
check(f["imu"] == "base_link", f"Imu frame_id {f['imu']!r}, expected 'base_link'")
check(f["velocity"] != "", "Velocity frame_id is empty")
for k in ("quaternion_norm", "imu_quaternion_norm"):
    v = seen[k]
    check(v is not None and abs(v - 1.0) < 1e-6, f"{k} = {v}, expected 1")
az = seen["imu_linear_acceleration_z"]
check(az is not None and abs(az - 9.81) <= 1.0, f"Imu linear_acceleration.z = {az}, expected 9.81 +- 1.0")
check(seen["last_stamp"] is not None and 2.5 <= seen["last_stamp"] <= 6.0,
      f"last Pose stamp {seen['last_stamp']} s, expected 2.5..6 s (the plant's time)")
check(seen["last_z"] is not None and 1.0 <= seen["last_z"] <= 3.0, f"last z seen {seen['last_z']}, expected 1..3 m")
check(seen["commands_sent"] >= 100, f"only {seen['commands_sent']} commands sent")
# What the plant announced in discovery, as a ROS 2 tool sees it (docs/ros2.md, What is on the wire):
# USER_DATA with the enclave key (else `ros2 node list` ignores it), and its endpoints with ROS type
# names, RELIABLE VOLATILE, XCDR1.
remote = seen["remote"]
check(remote["participants"] and all("enclave=/;" in u for u in remote["participants"]),
      f"remote participant USER_DATA {remote['participants']}, expected 'enclave=/;'")
expected = {("writer", "rt/drone/Pose"): "geometry_msgs::msg::dds_::PoseStamped_",
            ("writer", "rt/drone/Velocity"): "geometry_msgs::msg::dds_::TwistStamped_",
            ("writer", "rt/drone/Imu"): "sensor_msgs::msg::dds_::Imu_",
            ("writer", "rt/clock"): "rosgraph_msgs::msg::dds_::Clock_",
            ("reader", "rt/drone/motor_commands"): "std_msgs::msg::dds_::Float64MultiArray_"}
for (kind, topic), type_name in expected.items():
    eps = [e for e in remote["endpoints"] if e["kind"] == kind and e["topic"] == topic]
    check(len(eps) == 1, f"{len(eps)} remote {kind}s on {topic}, expected 1")
    for e in eps:
        check(e["type"] == type_name, f"{topic}: type {e['type']!r}, expected {type_name!r}")
        check(e["reliable"] and not e["transient_local"], f"{topic}: {kind} not RELIABLE VOLATILE: {e}")
        check(e["xcdr"][:1] == [1], f"{topic}: {kind} data representation {e['xcdr']}, expected XCDR1 first")

rows = list(csv.DictReader(open(sys.argv[2])))
for col in ("t", "z", "cmd1", "cmd2", "cmd3", "cmd4"):
    check(col in rows[0], f"CSV has no column {col}")
if not errors:
    t = [float(r["t"]) for r in rows]
    z = [float(r["z"]) for r in rows]
    cmd = [[float(r[f"cmd{i}"]) for i in range(1, 5)] for r in rows]
    check(len(rows) == 601 and abs(t[-1] - 6.0) < 1e-9, f"{len(rows)} rows up to t = {t[-1]}, expected 601 to 6 s")
    driven = [i for i, u in enumerate(cmd) if u[0] > 0.0]
    check(len(driven) >= 100, f"cmd1 > 0 on only {len(driven)} rows")
    # On the ground (rotors stopped) until the first foreign command is applied; that can already
    # be at row 0 when discovery beats the plant's first 10 ms.
    first = driven[0] if driven else len(z) - 1
    check(all(v == 0.0 for v in z[:first + 1]), f"z not 0 up to the first applied command (row {first})")
    check(all(u[0] > 0.0 for u in cmd[-50:]), "cmd1 not > 0 on the last 50 rows")
    check(all(u[0] == u[1] == u[2] == u[3] for u in cmd), "the four applied commands differ (foreign sends equal speeds)")
    check(all(3000.0 <= u[0] <= 8000.0 for u in (cmd[i] for i in driven)),
          "an applied command outside 3000..8000 rad/s (hover is 4830)")
    changes = sum(1 for i in range(1, len(cmd)) if cmd[i] != cmd[i - 1])
    check(changes >= 100, f"the applied command changed only {changes} times (foreign sends at 50 Hz)")
    check(1.0 <= z[-1] <= 3.0, f"final z = {z[-1]} m, expected 1..3 m")
    check(max(z) <= 3.0, f"highest z = {max(z)} m, expected <= 3 m")
    # The z the foreign node decoded at its last Pose stamp is the z the plant recorded then.
    ls = seen["last_stamp"]
    k = min(range(len(t)), key=lambda i: abs(t[i] - ls))
    check(abs(t[k] - ls) < 1e-6 and z[k] == seen["last_z"],
          f"foreign last z {seen['last_z']} at {ls} s, plant recorded z = {z[k]} at {t[k]} s")
    print(f"plant: {len(driven)} rows under foreign commands, {changes} command changes, "
          f"z from {z[0]} to {z[-1]:.3f} m (max {max(z):.3f}), last cmd {cmd[-1][0]:.1f} rad/s")
for e in errors:
    print("  -", e)
sys.exit(1 if errors else 0)
EOF
echo "PASS [foreign.drives_plant]"
