#!/usr/bin/env bash
# Ctrl-C (SIGINT) during a long in-process run: exit 130, the CSV holds what ran and run.mcap is a
# finished file (it ends with the MCAP magic, after the summary and footer).
set -euo pipefail
bin="$1"; src="$2"
tmp="$(mktemp -d)"
pid=""
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
sed 's/duration_s: 15/duration_s: 100000/' "$src/scenarios/paper/altitude_step.yaml" > "$tmp/long.yaml"
"$bin" run "$tmp/long.yaml" --out "$tmp/run" --no-plots > "$tmp/log" 2>&1 &
pid=$!
for _ in $(seq 100); do [ -s "$tmp/run/run.mcap" ] && break; sleep 0.05; done
sleep 1
kill -INT "$pid"
set +e
wait "$pid"; rc=$?
set -e
pid=""
[ "$rc" -eq 130 ] || { cat "$tmp/log"; echo "FAIL: expected exit 130, got $rc"; exit 1; }
rows=$(($(wc -l < "$tmp/run/trajectory.csv") - 1))
[ "$rows" -gt 1000 ] || { echo "FAIL: only $rows rows recorded"; exit 1; }
[ "$(tail -c 8 "$tmp/run/run.mcap" | od -An -tx1 | tr -d ' \n')" = "894d434150300d0a" ] \
  || { echo "FAIL: run.mcap does not end with the MCAP magic"; exit 1; }
grep -q "interrupted" "$tmp/log" || { echo "FAIL: no message about the interruption"; exit 1; }
echo "ok: interrupted after $rows ticks; files finished"
