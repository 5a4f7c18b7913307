#!/usr/bin/env bash
# A run's run.mcap read back by the MCAP reference reader (tools/mcap_verify: @mcap/core from npm with
# the Foxglove ROS 2 CDR decoder), never by our own code: message counts against the rates, decoded
# values against trajectory.csv, and the ros2 bag metadata.yaml beside it.
set -euo pipefail
bin="$1"; src="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
verify="$src/tools/mcap_verify"
bash "$verify/install.sh"
"$bin" run "$src/scenarios/paper/altitude_step.yaml" --out "$tmp/run" --no-plots > /dev/null
node "$verify/verify.mjs" "$tmp/run/run.mcap" > "$tmp/summary.json"
/usr/bin/python3 - "$tmp/summary.json" "$tmp/run/trajectory.csv" "$tmp/run/metadata.yaml" <<'PY'
import csv, json, sys
summary = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
meta = open(sys.argv[3]).read()
def fail(msg):
    print("FAIL:", msg); sys.exit(1)
if summary["profile"] != "ros2": fail("profile is %r" % summary["profile"])
ch = summary["channels"]
# 15 s at 100 Hz plant (ticks 0..1500) and 50 Hz controller (steps at even ticks):
# 4 x 1501 + 2 x 751 = 7506 messages, and the plant status once per simulated second (no command
# was refused): 16; /tf at every tick: 1501; the robot description, /tf_static and the scene once:
# 9026 in all.
expected = {"/clock": 1501, "/drone/Pose": 1501, "/drone/Velocity": 1501, "/drone/Imu": 1501,
            "/drone/controller_status": 751, "/drone/motor_commands": 751, "/drone/plant_status": 16,
            "/tf": 1501, "/drone/robot_description": 1, "/tf_static": 1, "/drone/scene": 1}
for topic, n in expected.items():
    got = ch[topic]["last"]["sequence"]
    if got != n: fail("%s: %d messages, expected %d" % (topic, got, n))
last, first = ch["/drone/Pose"]["last"], ch["/drone/Pose"]["first"]
if last["logTime"] != "15000000000": fail("log time is not simulated time: %s" % last["logTime"])
for msg, row in ((first, rows[0]), (last, rows[-1])):
    p = msg["message"]["pose"]["position"]
    for axis in "xyz":
        if float(row[axis]) != p[axis]: fail("Pose %s %r != CSV %r" % (axis, p[axis], row[axis]))
# The last status (t = 15 s) counts the commands of the steps at t = 0, 0.02, ..., 14.98 s: 750, none
# clamped or refused (uint64 fields decode as bigints, shown as strings).
ps = ch["/drone/plant_status"]["last"]["message"]
if (ps["commands_accepted"], ps["commands_clamped"], ps["commands_rejected_length"],
        ps["commands_rejected_non_finite"], ps["last_problem"]) != ("750", "0", "0", "0", ""):
    fail("last plant status %r, expected 750 accepted and nothing refused" % ps)
cs = ch["/drone/controller_status"]["last"]["message"]
if cs["rejected_non_finite"] != "0" or cs["rejected_stamp_backwards"] != "0":
    fail("controller status counts refused sensor messages in a clean run: %r" % cs)
cmd = ch["/drone/motor_commands"]["last"]["message"]["data"]
if [float(rows[-2]["cmd%d" % i]) for i in range(1, 5)] != cmd and [float(rows[-1]["cmd%d" % i]) for i in range(1, 5)] != cmd:
    fail("last motor command %r not in the CSV" % cmd)
for needle in ("storage_identifier: mcap", "relative_file_paths:", "- run.mcap", "message_count: 9026",
               "name: /drone/Pose", "type: geometry_msgs/msg/PoseStamped"):
    if needle not in meta: fail("metadata.yaml lacks %r" % needle)
print("ok: counts match the rates, values match trajectory.csv, metadata.yaml describes the bag")
PY
