#!/usr/bin/env python3
"""REP-2016 type hashes (RIHS01) of ros2/quadcosim_msgs, computed here from the .msg files, against the
ones quadcosim puts on the wire (dds/type_hash.hpp, printed by type_hash_print).

Usage: type_hashes.py TYPE_HASH_PRINT MSG_DIR

This is a second implementation of what rosidl_generator_type_description does, written from REP-2016
and type_description_interfaces (FieldType ids), sharing no code with quadcosim's C++ one. It is first
checked against hashes that ROS 2 builds generated for standard types (the values are those of
src/dds/type_hash_test.cpp, sources [J1] [K1] [Z1] there: rosidl's <type>__description.c files of a
Jazzy workspace and of micro-ROS), so a hash it computes for a quadcosim_msgs type is the one rosidl
would generate from the same .msg file. Exit 0 when every hash agrees; else each difference is named.
"""
import hashlib
import json
import os
import re
import subprocess
import sys

# type_description_interfaces/msg/FieldType: element ids; +48 fixed array, +96 bounded sequence,
# +144 unbounded sequence.
FIELD_TYPE_ID = {
    "nested": 1, "int8": 2, "uint8": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7, "int64": 8,
    "uint64": 9, "float32": 10, "float64": 11, "char": 13, "bool": 15, "byte": 16, "string": 17, "wstring": 18,
}
# rosidl_adapter: .msg `char` is uint8.
ALIASES = {"char": "uint8"}

# The standard types the quadcosim_msgs types use, as their .msg files in ROS 2 Jazzy
# (ros2/rcl_interfaces builtin_interfaces, ros2/common_interfaces std_msgs, geometry_msgs, sensor_msgs);
# defaults and comments left out: they are not part of a hash.
STANDARD_MSGS = {
    "builtin_interfaces/msg/Time": "int32 sec\nuint32 nanosec",
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "std_msgs/msg/MultiArrayDimension": "string label\nuint32 size\nuint32 stride",
    "std_msgs/msg/MultiArrayLayout": "MultiArrayDimension[] dim\nuint32 data_offset",
    "std_msgs/msg/Float64MultiArray": "MultiArrayLayout layout\nfloat64[] data",
    "geometry_msgs/msg/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/msg/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/msg/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/msg/Pose": "Point position\nQuaternion orientation",
    "geometry_msgs/msg/PoseStamped": "std_msgs/Header header\nPose pose",
    "geometry_msgs/msg/Twist": "Vector3 linear\nVector3 angular",
    "geometry_msgs/msg/TwistStamped": "std_msgs/Header header\nTwist twist",
    "sensor_msgs/msg/Imu": (
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
        "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
        "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance"),
}
# Hashes rosidl generated for them in ROS 2 builds (see the module docstring).
REFERENCE = {
    "builtin_interfaces/msg/Time": "b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "std_msgs/msg/Header": "f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "std_msgs/msg/MultiArrayDimension": "5e773a60a4c7fc8a54985f307c7837aa2994252a126c301957a24e31282c9cbe",
    "std_msgs/msg/MultiArrayLayout": "4c66e6f78e740ac103a94cf63259f968e48c617e7699e829b63c21a5cb50dac6",
    "std_msgs/msg/Float64MultiArray": "1025ddc6b9552d191f89ef1a8d2f60f3d373e28b283d8891ddcc974e8c55397f",
    "geometry_msgs/msg/Point": "6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881",
    "geometry_msgs/msg/Quaternion": "8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684",
    "geometry_msgs/msg/Pose": "d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa",
    "geometry_msgs/msg/PoseStamped": "10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
    "geometry_msgs/msg/Vector3": "cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d",
    "geometry_msgs/msg/Twist": "9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    "geometry_msgs/msg/TwistStamped": "5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64",
    "sensor_msgs/msg/Imu": "7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b",
}

FIELD = re.compile(r"^([A-Za-z][\w/]*)(?:<=(\d+))?(?:\[(<=)?(\d*)\])?$")


def parse_msg(text, package):
    """The fields of a .msg text: [(name, type description dict, nested type or None)]."""
    fields = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        if "=" in words[1] or (len(words) > 2 and words[2].startswith("=")):
            continue  # a constant: not part of the hash (a third word without '=' is a default: neither)
        type_text, name = words[0], words[1]
        m = FIELD.match(type_text)
        if not m:
            raise ValueError(f"{package}: cannot read the type of '{raw}'")
        base, string_bound, bounded, size = m.groups()
        base = ALIASES.get(base, base)
        nested = None
        if base in FIELD_TYPE_ID:
            type_id = FIELD_TYPE_ID[base]
            if string_bound is not None:
                type_id = {"string": 21, "wstring": 22}[base]
        else:
            if base == "Header":
                base = "std_msgs/Header"
            pkg, _, typ = base.rpartition("/")
            nested = f"{pkg or package}/msg/{typ}"
            type_id = FIELD_TYPE_ID["nested"]
        capacity = 0
        if size == "":  # T[]
            type_id += 144
        elif size is not None:  # T[N] or T[<=N]
            type_id += 96 if bounded else 48
            capacity = int(size)
        fields.append((name, {"type_id": type_id, "capacity": capacity,
                              "string_capacity": int(string_bound or 0), "nested_type_name": nested or ""}, nested))
    return fields


def description(name, definitions):
    return {"type_name": name, "fields": [{"name": n, "type": t} for n, t, _ in definitions[name]]}


def rihs01(name, definitions):
    """RIHS01_ + SHA-256 of the type's description and those it references (sorted by name), as JSON
    with Python's default separators and the keys in the order above."""
    referenced, todo = set(), [nested for _, _, nested in definitions[name] if nested]
    while todo:
        t = todo.pop()
        if t in referenced:
            continue
        referenced.add(t)
        todo.extend(nested for _, _, nested in definitions[t] if nested)
    doc = {"type_description": description(name, definitions),
           "referenced_type_descriptions": [description(t, definitions) for t in sorted(referenced)]}
    return "RIHS01_" + hashlib.sha256(json.dumps(doc).encode("utf-8")).hexdigest()


def main():
    printer, msg_dir = sys.argv[1], sys.argv[2]
    definitions = {name: parse_msg(text, name.split("/")[0]) for name, text in STANDARD_MSGS.items()}
    problems = []
    for name, want in REFERENCE.items():
        got = rihs01(name, definitions)
        if got != "RIHS01_" + want:
            problems.append(f"this implementation: {name} hashes to {got}, rosidl to RIHS01_{want}")
    if problems:  # the implementation itself is wrong: nothing below could be trusted
        print("\n".join(problems))
        return 1
    ours = sorted(f[:-4] for f in os.listdir(msg_dir) if f.endswith(".msg"))
    for t in ours:
        with open(os.path.join(msg_dir, t + ".msg"), encoding="utf-8") as f:
            definitions[f"quadcosim_msgs/msg/{t}"] = parse_msg(f.read(), "quadcosim_msgs")
    names = [f"quadcosim_msgs/msg/{t}" for t in ours]
    out = subprocess.run([printer, *names], capture_output=True, text=True, check=False)
    if out.returncode != 0:
        print(f"type_hash_print failed: {out.stderr.strip()}")
        return 1
    printed = dict(line.split() for line in out.stdout.splitlines())
    for name in names:
        want = rihs01(name, definitions)
        if printed.get(name) != want:
            problems.append(f"{name}: quadcosim puts {printed.get(name)} on the wire, its .msg file hashes to {want}")
        else:
            print(f"{name} {want}")
    if problems:
        print("\n".join(problems))
        return 1
    print(f"{len(REFERENCE)} standard types as rosidl hashes them; {len(names)} quadcosim_msgs types agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
