#!/usr/bin/python3
"""Usage: same_metrics.py A/metrics.json B/metrics.json

Exit 0 when the two files hold the same judgement: the same JSON besides "provenance" (what flew and
how, which names the command line, the transport and the host, so it differs between two hosts of one
run by design). Numbers compare by their text (Python's shortest round trip of the parsed double, ints
as ints), so equal here is equal bit for bit. Otherwise prints the top-level keys that differ, exit 1.
"""
import json
import sys


def judgement(path):
    with open(path, encoding="utf-8") as f:
        m = json.load(f)
    m.pop("provenance", None)
    return m


def main(a_path, b_path):
    a, b = judgement(a_path), judgement(b_path)
    if json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True):
        return 0
    keys = sorted(k for k in set(a) | set(b) if json.dumps(a.get(k), sort_keys=True) != json.dumps(b.get(k), sort_keys=True))
    print(f"{a_path} and {b_path} differ besides provenance, in: {', '.join(keys)}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
