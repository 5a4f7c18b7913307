# shellcheck shell=bash
# same_recording A B (sourced by the case scripts; uses $src, the source folder, and $tmp): whether two
# run.mcap files hold the same messages, for a run over DDS against the same run in-process.
# Byte for byte first; else, read by the
# MCAP reference reader (tools/mcap_verify), every topic must hold the same messages with the same log
# times in the same order: only the interleaving of topics may differ (over DDS a controller's answer
# can be recorded before or after the last of the plant's messages of its tick), and PlantStatus's
# commands_stale, which over DDS counts the controller's second answers to ticks the plant sent again
# while it waited (a busy machine), and is 0 in-process (docs/cosimulation.md).
same_recording() {
  cmp -s "$1" "$2" && return 0
  local verify="${src:?}/tools/mcap_verify"
  bash "$verify/install.sh" > /dev/null
  local topics
  topics=$(node "$verify/verify.mjs" "$1" | /usr/bin/python3 -c 'import json, sys; print(" ".join(json.load(sys.stdin)["channels"]))')
  # shellcheck disable=SC2086
  node "$verify/dump.mjs" "$1" $topics > "${tmp:?}/recording_a.json" || return 1
  # shellcheck disable=SC2086
  node "$verify/dump.mjs" "$2" $topics > "$tmp/recording_b.json" || return 1
  /usr/bin/python3 - "$tmp/recording_a.json" "$tmp/recording_b.json" <<'PY' || return 1
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
def messages(d, topic):
    out = []
    for m in (d[topic] or {"messages": []})["messages"]:
        body = dict(m["message"])
        if topic.endswith("/plant_status"):
            body.pop("commands_stale", None)
        out.append((m["logTime"], body))
    return out
for topic in a:
    ma, mb = messages(a, topic), messages(b, topic)
    if ma != mb:
        first = next((x, y) for x, y in zip(ma + [None], mb + [None]) if x != y)
        print("recordings differ on", topic, len(ma), len(mb), "first:", first); sys.exit(1)
print("run.mcap: the same messages on every topic; the topics interleaved differently")
PY
}
