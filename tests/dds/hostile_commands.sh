#!/usr/bin/env bash
# A controller that sends wrong-length, NaN and out-of-range motor commands to `quadcosim plant`
# over DDS (lockstep, 1 s): the plant must refuse and clamp exactly what was sent, keep a finite
# state, and publish the counts on /drone/plant_status (checked in its MCAP recording with the MCAP
# reference reader when Node.js is there). Usage: hostile_commands.sh BINARY HOSTILE_CONTROLLER SOURCE_DIR DOMAIN_ID
bin="$1"; hostile="$2"; src="$3"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" hostile_commands "$4"

mkdir -p "$tmp/bag"
"$hostile" 2 > "$tmp/hostile.log" 2>&1 &
pids+=($!)
hostile_pid=$!
"$bin" plant --duration 1 --timeout 20 --record "$tmp/plant.csv" --mcap "$tmp/bag/plant.mcap" > "$tmp/plant.log" 2>&1 \
  || fail "plant failed"
wait "$hostile_pid" || fail "hostile controller saw no plant"

# 1 s at 100 Hz, commands awaited on ticks 0, 2, ..., 100: 51 answers, kinds cycling valid, short,
# NaN, clamp: 13 + 13 + 13 + 12.
grep -q "sent valid 13 short 13 nan 13 clamp 12" "$tmp/hostile.log" || fail "hostile controller: $(cat "$tmp/hostile.log")"
grep -q "commands received 51, rejected 26, clamped 12, stale 0" "$tmp/plant.log" || fail "plant counts"
grep -q "plant: motor command rejected (3 values, expected 4 rotor speeds), last good command held; 1 rejected so far" \
  "$tmp/plant.log" || fail "no log line for the first rejected command"
# Rate-limited: 26 rejections and 12 clamps give one line each.
[ "$(grep -c 'motor command rejected' "$tmp/plant.log")" -eq 1 ] || fail "rejections not rate-limited"
[ "$(grep -c 'motor command clamped' "$tmp/plant.log")" -eq 1 ] || fail "clamps not rate-limited"
# The state stays finite: every cell of every row is a number (the openloop-only columns aside).
/usr/bin/python3 - "$tmp/plant.csv" <<'PY' || fail "non-finite state in the plant's CSV"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 101, len(rows)
for r in rows:
    for c in ("x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r", "w1", "w2", "w3", "w4",
              "cmd1", "cmd2", "cmd3", "cmd4"):
        assert math.isfinite(float(r[c])), (r["t"], c, r[c])
    for c in ("cmd1", "cmd2", "cmd3", "cmd4"):
        assert 0 <= float(r[c]) <= 12000, (r["t"], c, r[c])
PY
if command -v node > /dev/null && [ -d "$src/tools/mcap_verify/node_modules" ]; then
  node "$src/tools/mcap_verify/verify.mjs" "$tmp/bag/plant.mcap" > "$tmp/summary.json" || fail "unreadable MCAP"
  /usr/bin/python3 - "$tmp/summary.json" <<'PY' || fail "plant_status in the recording"
import json, sys
ch = json.load(open(sys.argv[1]))["channels"]
last = ch["/drone/plant_status"]["last"]["message"]
# Published at t = 1 s, before that tick's command: the 50 answers of ticks 0..98 (i = 0..49):
# valid 13, short 13, NaN 12, clamp 12; the newest problem is i = 49, a short one.
want = {"commands_accepted": "25", "commands_clamped": "12", "commands_rejected_length": "13",
        "commands_rejected_non_finite": "12", "last_problem": "3 values, expected 4 rotor speeds"}
got = {k: last[k] for k in want}
assert got == want, got
assert last["header"]["stamp"] == {"sec": 1, "nanosec": 0}, last["header"]
# One status on the tick after each of the 37 refused or clamped answers before t = 1 s (odd ticks),
# and the periodic ones at t = 0 and 1 s.
assert ch["/drone/plant_status"]["count"] == 39, ch["/drone/plant_status"]["count"]
PY
fi
echo "ok: refused and clamped commands counted, logged once each, state finite, status recorded"
