#!/usr/bin/env bash
# MCAP interop: files written by quadcosim's McapWriter (through mcap_sample, the way the recorder
# writes) are read back by the MCAP reference reader (@mcap/core + Foxglove's ROS 2 decoders, in
# tools/mcap_verify) and what it decodes must equal what was written.
#   usage: mcap_interop_test.sh MCAP_SAMPLE_BINARY TOOLS_MCAP_VERIFY_DIR
# Cases: a zstd multi-chunk file (indexed and streaming reads), an uncompressed one, one without
# messages, a recorder
# killed with SIGKILL after a flush (streaming recovery gets exactly the flushed messages), and a
# valid file cut in the middle of its last chunk (streaming recovery gets every complete chunk).
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 MCAP_SAMPLE_BINARY TOOLS_MCAP_VERIFY_DIR" >&2
  exit 2
fi
SAMPLE=$1
VERIFY_DIR=$2

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

bash "$VERIFY_DIR/install.sh" || fail "cannot install the MCAP reader's npm packages"

verify() {  # verify [--stream] FILE > JSON
  node "$VERIFY_DIR/verify.mjs" "$@"
}

# Compares a reader summary with what mcap_sample wrote.
#   check.py EXPECTED.json READ.json CASE
cat >"$TMP/check.py" <<'EOF'
import json, sys

expected = json.load(open(sys.argv[1]))
got = json.load(open(sys.argv[2]))
case = sys.argv[3]
errors = []

def need(cond, what):
    if not cond:
        errors.append(what)

def same_message(topic, which, want, have):
    need(have is not None, f"{topic}: no {which} message")
    if have is None:
        return
    need(have["sequence"] == want["sequence"], f"{topic} {which}: sequence {have['sequence']} != {want['sequence']}")
    need(have["logTime"] == want["log_time"], f"{topic} {which}: log time {have['logTime']} != {want['log_time']}")
    need(have["publishTime"] == want["log_time"], f"{topic} {which}: publish time {have['publishTime']}")
    # Exact equality of the decoded tree (JSON numbers as Python floats: the doubles round-trip).
    need(have["message"] == want["message"],
         f"{topic} {which}: decoded\n  {json.dumps(have['message'], sort_keys=True)}\nwritten\n  "
         f"{json.dumps(want['message'], sort_keys=True)}")

need(got["profile"] == expected["profile"], f"profile {got['profile']!r}")
need(got["library"] == expected["library"], f"library {got['library']!r}")
need(got["trailingByteMessages"] == 0, f"{got['trailingByteMessages']} messages longer than their schema")
need(set(got["channels"]) == set(expected["channels"]), f"topics {sorted(got['channels'])}")

if case == "truncated":
    # Every complete chunk is recovered: the expected count comes from the intact file's index.
    want_total = int(sys.argv[4])
    need(got["messageCount"] == want_total, f"recovered {got['messageCount']} messages, want {want_total}")
    need(got["complete"] is False, "a cut file read as complete")
else:
    need(got["messageCount"] == expected["messages"], f"{got['messageCount']} messages, wrote {expected['messages']}")

for topic, want in expected["channels"].items():
    have = got["channels"].get(topic)
    if have is None:
        continue
    need(have["messageEncoding"] == "cdr", f"{topic}: message encoding {have['messageEncoding']!r}")
    need(have["schemaEncoding"] == "ros2msg", f"{topic}: schema encoding {have['schemaEncoding']!r}")
    need(have["schemaName"] == want["schema"], f"{topic}: schema {have['schemaName']!r}")
    need("offered_qos_profiles" in have["metadata"], f"{topic}: no offered_qos_profiles")
    if want["count"] == 0:
        need(have["count"] == 0, f"{topic}: {have['count']} messages, wrote none")
        continue
    same_message(topic, "first", want["first"], have.get("first"))
    if case == "truncated":
        # A prefix of each channel: sequences 1..count without gaps.
        need(have["count"] > 0, f"{topic}: nothing recovered")
        need(have["last"]["sequence"] == have["count"], f"{topic}: last sequence {have['last']['sequence']} of {have['count']}")
        continue
    need(have["count"] == want["count"], f"{topic}: {have['count']} messages, wrote {want['count']}")
    same_message(topic, "last", want["last"], have.get("last"))

if got["mode"] == "indexed":
    st = got["statistics"]
    need(st is not None, "no Statistics record")
    if st:
        need(int(st["messageCount"]) == expected["messages"], f"statistics: {st['messageCount']} messages")
        need(st["channelCount"] == len(expected["channels"]) and st["schemaCount"] == len(expected["channels"]),
             f"statistics: {st['channelCount']} channels, {st['schemaCount']} schemas")
        need(st["chunkCount"] == len(got["chunks"]), f"statistics: {st['chunkCount']} chunks")
        for topic, want in expected["channels"].items():
            need(int(st["channelMessageCounts"].get(topic, -1)) == want["count"], f"statistics: count of {topic}")
    need(sum(c["messages"] for c in got["chunks"]) == expected["messages"], "message indexes do not cover every message")
    need(got["dataSectionCrc"]["ok"], f"data section CRC {got['dataSectionCrc']}")
    need(got["summaryCrcChecked"], "footer has no summary CRC")
    groups = [3, 4, 8, 11] if expected["messages"] else [3, 4, 11]  # no Chunk Index group without chunks
    need(got["summaryOffsetOpcodes"] == groups, f"summary offsets for opcodes {got['summaryOffsetOpcodes']}")
if got["mode"] == "stream" and case in ("full", "plain", "empty"):
    need(got["complete"] is True and got["bytesRemaining"] == 0, "streaming read did not end at a valid footer")

if errors:
    print(f"[{case}] " + "\n".join(errors), file=sys.stderr)
    sys.exit(1)
print(f"[{case}] ok: {got['mode']} read, {got['messageCount']} messages on {len(got['channels'])} channels")
EOF

check() {  # check EXPECTED READ CASE [ARGS...]
  python3 "$TMP/check.py" "$@" || fail "reader output differs from what was written (case $3, output in $2)"
}

# 1. zstd, several chunks, closed normally: indexed and streaming reads.
"$SAMPLE" full "$TMP/full.mcap" "$TMP/full.json" || fail "mcap_sample full"
verify "$TMP/full.mcap" >"$TMP/full.indexed.json" || fail "indexed read of full.mcap"
check "$TMP/full.json" "$TMP/full.indexed.json" full
verify --stream "$TMP/full.mcap" >"$TMP/full.stream.json" || fail "streaming read of full.mcap"
check "$TMP/full.json" "$TMP/full.stream.json" full
chunks=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["chunks"]))' "$TMP/full.indexed.json")
[[ $chunks -ge 3 ]] || fail "expected several chunks, got $chunks"
python3 -c 'import json,sys; c=json.load(open(sys.argv[1]))["chunks"]; sys.exit(any(x["compression"] != "zstd" for x in c))' \
  "$TMP/full.indexed.json" || fail "chunks not zstd"

# 2. Uncompressed chunks.
"$SAMPLE" plain "$TMP/plain.mcap" "$TMP/plain.json" || fail "mcap_sample plain"
verify "$TMP/plain.mcap" >"$TMP/plain.indexed.json" || fail "indexed read of plain.mcap"
check "$TMP/plain.json" "$TMP/plain.indexed.json" plain
python3 -c 'import json,sys; c=json.load(open(sys.argv[1]))["chunks"]; sys.exit(any(x["compression"] != "" for x in c))' \
  "$TMP/plain.indexed.json" || fail "plain chunks are compressed"

# 3. No message at all: still a valid, indexed file.
"$SAMPLE" empty "$TMP/empty.mcap" "$TMP/empty.json" || fail "mcap_sample empty"
verify "$TMP/empty.mcap" >"$TMP/empty.indexed.json" || fail "indexed read of empty.mcap"
check "$TMP/empty.json" "$TMP/empty.indexed.json" empty
verify --stream "$TMP/empty.mcap" >"$TMP/empty.stream.json" || fail "streaming read of empty.mcap"
check "$TMP/empty.json" "$TMP/empty.stream.json" empty

# 4. The recorder is SIGKILLed after flush(): no summary, no footer; the flushed messages survive.
set +e
{ "$SAMPLE" killed "$TMP/killed.mcap" "$TMP/killed.json"; rc=$?; } 2>/dev/null  # (quiet "Killed")
set -e
[[ $rc -eq 137 ]] || fail "mcap_sample killed: expected death by SIGKILL (137), got $rc"
if verify "$TMP/killed.mcap" >/dev/null 2>&1; then fail "the killed file read as a finished, indexed file"; fi
verify --stream "$TMP/killed.mcap" >"$TMP/killed.stream.json" || fail "streaming read of killed.mcap"
check "$TMP/killed.json" "$TMP/killed.stream.json" killed
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(d["complete"] is not False)' \
  "$TMP/killed.stream.json" || fail "killed file read as complete"

# 5. A valid file cut in the middle of its last chunk (a SIGKILL while the chunk was being written):
#    every earlier chunk is recovered.
read -r cut recoverable < <(python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
last = d["chunks"][-1]
print(int(last["offset"]) + int(last["length"]) // 2, d["messageCount"] - last["messages"])' "$TMP/full.indexed.json")
head -c "$cut" "$TMP/full.mcap" >"$TMP/cut.mcap"
if verify "$TMP/cut.mcap" >/dev/null 2>&1; then fail "the cut file read as a finished, indexed file"; fi
verify --stream "$TMP/cut.mcap" >"$TMP/cut.stream.json" || fail "streaming read of cut.mcap"
check "$TMP/full.json" "$TMP/cut.stream.json" truncated "$recoverable"

echo "mcap interop: all cases passed"
