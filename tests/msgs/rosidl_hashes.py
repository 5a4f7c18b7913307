#!/usr/bin/env python3
"""The type hashes quadcosim puts on the wire for ros2/quadcosim_msgs (dds/type_hash.hpp, printed by
type_hash_print) against the ones ROS 2's own generator computes from the package's .msg files:
rosidl_adapter turns each .msg into IDL, rosidl_generator_type_description hashes it (REP-2011 /
RIHS01), with the standard types it references (std_msgs, geometry_msgs, builtin_interfaces) taken
from the ROS 2 at hand.

Usage: rosidl_hashes.py TYPE_HASH_PRINT MSG_DIR

Where ROS 2 comes from:
  - a sourced ROS 2 installation (AMENT_PREFIX_PATH): its rosidl Python packages, and the type
    descriptions (share/<package>/msg/<Type>.json) its build installed;
  - else QUADCOSIM_ROS2_SOURCES, a folder holding checkouts of ros2/rosidl, ros2/common_interfaces and
    ros2/rcl_interfaces (a Jazzy branch): the standard types' descriptions are generated from their .msg
    files first, as their build would (rosidl's parser needs python3-lark);
  - else the test is SKIPPED (exit 77), saying so.
Exit 0 when every hash agrees; else each difference is named (exit 1).
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile

SKIP = 77
# The standard types quadcosim_msgs references, by package, with the folder of its sources.
STANDARD = {
    "builtin_interfaces": ("rcl_interfaces/builtin_interfaces", ["Time"]),
    "std_msgs": ("common_interfaces/std_msgs", ["Header"]),
    "geometry_msgs": ("common_interfaces/geometry_msgs", ["Vector3", "Quaternion"]),
}


def import_rosidl(sources):
    if sources:
        for p in ("rosidl_adapter", "rosidl_parser", "rosidl_generator_type_description", "rosidl_pycommon",
                  "rosidl_cli"):
            sys.path.insert(0, str(sources / "rosidl" / p))
    from rosidl_adapter.msg import convert_msg_to_idl  # noqa: E402
    from rosidl_generator_type_description import generate_type_hash  # noqa: E402
    return convert_msg_to_idl, generate_type_hash


def generate(convert, hash_package, name, package_dir, types, out, includes):
    """The type descriptions (out/json/<name>/msg/<Type>.json) of `types` of the package at package_dir."""
    idl_dir = out / "idl" / name
    tuples = []
    for t in types:
        convert(package_dir, name, pathlib.Path("msg") / f"{t}.msg", idl_dir / "msg")
        tuples.append(f"{idl_dir}:msg/{t}.idl")
    args = out / f"{name}.json"
    args.write_text(json.dumps({"package_name": name, "output_dir": str(out / "json" / name), "idl_tuples": tuples,
                                "include_paths": [f"{k}:{v}" for k, v in includes.items()]}))
    hash_package(str(args))
    return out / "json" / name


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    printer, msg_dir = argv[1], pathlib.Path(argv[2]).resolve()
    sources = os.environ.get("QUADCOSIM_ROS2_SOURCES")
    sources = pathlib.Path(sources) if sources else None
    installed = [pathlib.Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    includes = {}
    for pkg in STANDARD:
        for share in installed:
            if (share / pkg / "msg" / f"{STANDARD[pkg][1][0]}.json").is_file():
                includes[pkg] = share / pkg
                break
    if len(includes) < len(STANDARD) and not (sources and (sources / "rosidl").is_dir()):
        print("SKIPPED: neither a sourced ROS 2 installation with the standard types' descriptions "
              "(AMENT_PREFIX_PATH) nor QUADCOSIM_ROS2_SOURCES (checkouts of ros2/rosidl, common_interfaces, "
              "rcl_interfaces) is present")
        return SKIP
    try:
        convert, hash_package = import_rosidl(sources if len(includes) < len(STANDARD) else None)
    except ImportError as e:
        print(f"SKIPPED: rosidl's Python packages do not import here ({e})")
        return SKIP
    types = sorted(p.stem for p in msg_dir.glob("*.msg"))
    with tempfile.TemporaryDirectory(prefix="rosidl_hashes_") as tmp:
        out = pathlib.Path(tmp)
        if len(includes) < len(STANDARD):
            includes = {}
            for pkg, (folder, needed) in STANDARD.items():  # in dependency order
                includes[pkg] = generate(convert, hash_package, pkg, sources / folder, needed, out, dict(includes))
        generated = generate(convert, hash_package, "quadcosim_msgs", msg_dir.parent, types, out, includes)
        rosidl = {}
        for t in types:
            doc = json.loads((generated / "msg" / f"{t}.json").read_text())
            first = doc["type_hashes"][0]
            rosidl[first["type_name"]] = first["hash_string"]
    printed = subprocess.run([printer, *sorted(rosidl)], check=True, capture_output=True, text=True).stdout
    ours = dict(line.split(" ", 1) for line in printed.splitlines())
    problems = [f"{name}: quadcosim announces {ours.get(name)}, rosidl generates {want}"
                for name, want in sorted(rosidl.items()) if ours.get(name) != want]
    for p in problems:
        print(p)
    if not problems:
        print(f"{len(rosidl)} quadcosim_msgs types: quadcosim's type hashes are rosidl's")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
