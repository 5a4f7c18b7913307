#!/usr/bin/env python3
"""Checks the vehicle's 3D topics of a run.mcap, as decoded by tools/mcap_verify/dump.mjs (the
independent npm reader), against the run's trajectory.csv and the vehicle's arm length.

  check_viz3d.py DUMP.json TRAJECTORY.csv NAMESPACE ARM_LENGTH_M [--frame world]

/tf: one transform per tick, parent `world`, child `<ns>/base_link`, stamped with the tick's time
(= the MCAP log time), translation and rotation equal to trajectory.csv's x, y, z and qx, qy, qz, qw
of the row with the same t, to the last bit (the CSV prints doubles in shortest round-trip form).
/tf_static: base_link -> rotor_1..4 at the arm length. robot_description: a URDF (parsed with
Python's xml) with base_link and four rotor links on fixed joints at the arm length, matching
/tf_static. The scene: one SceneUpdate with one frame-locked entity on base_link: five cubes (body
and four arms), four cylinders (rotor discs) centred over the rotors, one arrow.
"""
import csv
import json
import math
import sys
import xml.etree.ElementTree as ET


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


dump = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
ns = sys.argv[3]
arm = float(sys.argv[4])
world = sys.argv[6] if len(sys.argv) > 6 and sys.argv[5] == "--frame" else "world"
prefix = ns.strip("/") + "/" if ns.strip("/") else ""
base = prefix + "base_link"


def near(a, b):
    return abs(a - b) <= 1e-12 * max(1.0, abs(b))


# /tf against trajectory.csv, row by row (the CSV's t is k * period, printed in shortest form).
tf = dump.get("/tf")
if tf is None:
    fail("no /tf channel")
if tf["schemaName"] != "tf2_msgs/msg/TFMessage":
    fail("/tf schema %r" % tf["schemaName"])
if "depth: 100" not in tf["metadata"].get("offered_qos_profiles", ""):
    fail("/tf offered QoS is not depth 100: %r" % tf["metadata"])
msgs = tf["messages"]
if len(msgs) != len(rows):
    fail("/tf has %d messages, trajectory.csv %d rows" % (len(msgs), len(rows)))
for m, row in zip(msgs, rows):
    ts = m["message"]["transforms"]
    if len(ts) != 1:
        fail("/tf at %s: %d transforms, expected 1" % (m["logTime"], len(ts)))
    t = ts[0]
    stamp_ns = t["header"]["stamp"]["sec"] * 10**9 + t["header"]["stamp"]["nanosec"]
    if str(stamp_ns) != m["logTime"]:
        fail("/tf stamp %d != log time %s" % (stamp_ns, m["logTime"]))
    if round(float(row["t"]) * 1e9) != stamp_ns:
        fail("/tf stamp %d at CSV t = %s" % (stamp_ns, row["t"]))
    if t["header"]["frame_id"] != world or t["child_frame_id"] != base:
        fail("/tf frames %r -> %r, expected %r -> %r" % (t["header"]["frame_id"], t["child_frame_id"], world, base))
    tr, rot = t["transform"]["translation"], t["transform"]["rotation"]
    for key, col in (("x", "x"), ("y", "y"), ("z", "z")):
        if tr[key] != float(row[col]):
            fail("/tf translation.%s %r != CSV %s %r at t = %s" % (key, tr[key], col, row[col], row["t"]))
    for key, col in (("x", "qx"), ("y", "qy"), ("z", "qz"), ("w", "qw")):
        if rot[key] != float(row[col]):
            fail("/tf rotation.%s %r != CSV %s %r at t = %s" % (key, rot[key], col, row[col], row["t"]))

# /tf_static: the rotors.
st = dump.get("/tf_static")
if st is None or len(st["messages"]) != 1:
    fail("/tf_static: expected one message, got %r" % (st and len(st["messages"])))
if "durability: transient_local" not in st["metadata"].get("offered_qos_profiles", ""):
    fail("/tf_static offered QoS is not transient local")
statics = {t["child_frame_id"]: t for t in st["messages"][0]["message"]["transforms"]}
if sorted(statics) != [prefix + "rotor_%d" % i for i in range(1, 5)]:
    fail("/tf_static children %r" % sorted(statics))
for name, t in statics.items():
    tr = t["transform"]["translation"]
    if t["header"]["frame_id"] != base or not near(math.hypot(tr["x"], tr["y"]), arm) or tr["z"] != 0:
        fail("/tf_static %s: parent %r at %r, expected %r at %g m" % (name, t["header"]["frame_id"], tr, base, arm))

# robot_description: a URDF with the same rotors.
rd = dump.get(ns.rstrip("/") + "/robot_description")
if rd is None or len(rd["messages"]) != 1:
    fail("robot_description: expected one message")
if rd["schemaName"] != "std_msgs/msg/String":
    fail("robot_description schema %r" % rd["schemaName"])
robot = ET.fromstring(rd["messages"][0]["message"]["data"])
if robot.tag != "robot":
    fail("URDF root <%s>" % robot.tag)
links = [l.get("name") for l in robot.findall("link")]
if base not in links:
    fail("URDF has no link %r: %r" % (base, links))
rotors = [l for l in links if l.startswith(prefix + "rotor_")]
if len(rotors) != 4:
    fail("URDF rotor links %r" % rotors)
for j in robot.findall("joint"):
    child, parent = j.find("child").get("link"), j.find("parent").get("link")
    xyz = [float(v) for v in j.find("origin").get("xyz").split()]
    if j.get("type") != "fixed" or parent != base or child not in rotors:
        fail("URDF joint %r: %s %s -> %s" % (j.get("name"), j.get("type"), parent, child))
    if not near(math.hypot(xyz[0], xyz[1]), arm):
        fail("URDF rotor %s at %r, not at the arm length %g" % (child, xyz, arm))
    s = statics[child]["transform"]["translation"]
    if [s["x"], s["y"], s["z"]] != xyz:
        fail("URDF joint of %s at %r, /tf_static at %r" % (child, xyz, s))
if len(robot.findall("joint")) != 4:
    fail("URDF has %d joints" % len(robot.findall("joint")))
cyl = robot.findall("link/visual/geometry/cylinder")
if len(cyl) != 4:
    fail("URDF has %d cylinder visuals" % len(cyl))
radius = float(cyl[0].get("radius"))

# The scene.
sc = dump.get(ns.rstrip("/") + "/scene")
if sc is None or len(sc["messages"]) != 1:
    fail("scene: expected one message")
if sc["schemaName"] != "foxglove_msgs/msg/SceneUpdate" or "MSG: foxglove_msgs/CylinderPrimitive" not in sc["schemaText"]:
    fail("scene schema %r" % sc["schemaName"])
if sc["messages"][0]["logTime"] != "0":
    fail("scene log time %s" % sc["messages"][0]["logTime"])
u = sc["messages"][0]["message"]
if u["deletions"] or len(u["entities"]) != 1:
    fail("scene: %d deletions, %d entities" % (len(u["deletions"]), len(u["entities"])))
e = u["entities"][0]
if e["frame_id"] != base or e["frame_locked"] is not True or e["lifetime"] != {"sec": 0, "nanosec": 0}:
    fail("scene entity frame %r locked %r lifetime %r" % (e["frame_id"], e["frame_locked"], e["lifetime"]))
if (len(e["cubes"]), len(e["cylinders"]), len(e["arrows"])) != (5, 4, 1):
    fail("scene entity has %d cubes, %d cylinders, %d arrows" % (len(e["cubes"]), len(e["cylinders"]), len(e["arrows"])))
for c in e["cylinders"]:
    p = c["pose"]["position"]
    if not near(math.hypot(p["x"], p["y"]), arm) or not near(c["size"]["x"], 2 * radius):
        fail("scene rotor disc at %r size %r (arm %g, URDF radius %g)" % (p, c["size"], arm, radius))
for c in e["cubes"][1:]:
    if not near(c["size"]["x"], arm):
        fail("scene arm length %r" % c["size"])
print("ok: %d /tf transforms equal trajectory.csv; 4 rotors at %g m in /tf_static, the URDF and the scene"
      % (len(msgs), arm))
