#!/usr/bin/env bash
# The vehicle in 3D, in-process: run.mcap's /tf, /tf_static, robot_description and scene, read back
# by the independent npm reader (tools/mcap_verify/dump.mjs: @mcap/core with Foxglove's ROS 2
# decoders and the schema text stored in the file) and checked against trajectory.csv and the
# vehicle's arm length (tests/lib/check_viz3d.py). Two runs: the paper's '+' vehicle in /drone, and
# an 'x' vehicle with a 0.25 m arm in the root namespace (plain base_link).
set -euo pipefail
bin="$1"; src="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
verify="$src/tools/mcap_verify"
bash "$verify/install.sh"
"$bin" run "$src/scenarios/paper/roll_step.yaml" --out "$tmp/run" --no-plots > /dev/null
node "$verify/dump.mjs" "$tmp/run/run.mcap" /tf /tf_static /drone/robot_description /drone/scene > "$tmp/dump.json"
/usr/bin/python3 "$src/tests/lib/check_viz3d.py" "$tmp/dump.json" "$tmp/run/trajectory.csv" /drone 0.59

sed -e 's/^name: .*/name: x_root/' "$src/scenarios/paper/roll_step.yaml" > "$tmp/x.yaml"
cat >> "$tmp/x.yaml" <<'YAML'
vehicle:
  arm_length_m: 0.25
  layout: x
YAML
sed -i -e 's/^simulation:/simulation:\n  namespace: \//' "$tmp/x.yaml"
# The paper's gains were not tuned for this vehicle: a failed verdict (exit 1) is fine here.
"$bin" run "$tmp/x.yaml" --out "$tmp/x" --no-plots > "$tmp/x.log" 2>&1 || [ $? -eq 1 ] || { cat "$tmp/x.log"; exit 1; }
node "$verify/dump.mjs" "$tmp/x/run.mcap" /tf /tf_static /robot_description /scene > "$tmp/x.json"
/usr/bin/python3 "$src/tests/lib/check_viz3d.py" "$tmp/x.json" "$tmp/x/trajectory.csv" / 0.25
# 'x': the rotors on the diagonals (|x| = |y| = L / sqrt 2), none on an axis.
/usr/bin/python3 - "$tmp/x.json" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
for t in d["/tf_static"]["messages"][0]["message"]["transforms"]:
    tr = t["transform"]["translation"]
    assert abs(abs(tr["x"]) - 0.25 / math.sqrt(2)) < 1e-12 and abs(abs(tr["y"]) - 0.25 / math.sqrt(2)) < 1e-12, t
print("ok: 'x' layout rotors on the diagonals")
PY

# simulation.tf: false switches all of it off: no /tf, /tf_static, robot_description or scene.
sed -e 's/^simulation:/simulation:\n  tf: false/' "$src/scenarios/paper/roll_step.yaml" > "$tmp/off.yaml"
"$bin" run "$tmp/off.yaml" --out "$tmp/off" --no-plots > /dev/null
node "$verify/dump.mjs" "$tmp/off/run.mcap" /tf /tf_static /drone/robot_description /drone/scene /drone/Pose > "$tmp/off.json"
/usr/bin/python3 - "$tmp/off.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["/drone/Pose"] and len(d["/drone/Pose"]["messages"]) == 1501, "Pose missing"
# The recorder keeps its /tf channel (a plant elsewhere may publish it); nothing comes on it.
assert d["/tf"] is None or d["/tf"]["messages"] == [], "messages on /tf"
assert all(d[t] is None for t in ("/tf_static", "/drone/robot_description", "/drone/scene")), d
print("ok: simulation.tf: false records none of the 3D topics")
PY
