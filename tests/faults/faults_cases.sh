#!/usr/bin/env bash
# Faults with real processes, and plant and controller in two network namespaces.
# Usage: faults_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FLOOD_BINARY
# Each case runs on its own ROS_DOMAIN_ID and ends every process it started (trap), also on failure,
# including the processes inside network namespaces and the namespaces themselves.
# Times are compared on the monotonic clock (CLOCK_MONOTONIC: the nodes' steady clock and Python's
# time.monotonic()). Bounds and why they are what they are: docs/reliability.md.
# The netns cases need root and iproute2. When namespaces cannot be created they fail, unless
# QUADCOSIM_SKIP_NETNS=1, which makes them report SKIPPED (exit 77). The netns_nft cases also need
# nftables (nft, and nf_tables in the kernel); without it they report SKIPPED with the reason.
set -euo pipefail
bin="$1"; src="$2"; case_name="$3"; domain="$4"; flood="${5:-}"
export ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
py=/usr/bin/python3
hover="$src/tests/faults/hover.yaml"
# shellcheck source=../lib/same_recording.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/same_recording.sh"
tmp="$(mktemp -d)"
pids=()
namespaces=()
cleanup() {
  local rc=$?
  set +e  # end everything even if one step of the cleanup fails; keep the case's exit status
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  for ns in "${namespaces[@]}"; do
    for p in $(ip netns pids "$ns" 2>/dev/null); do kill -KILL "$p" 2>/dev/null || true; done
  done
  wait 2>/dev/null || true
  for ns in "${namespaces[@]}"; do ip netns del "$ns" 2>/dev/null || true; done
  rm -rf "$tmp"
  exit "$rc"
}
trap cleanup EXIT
fail() {
  echo "FAIL [$case_name]: $*"
  for f in "$tmp"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -25 "$f"; }; done
  exit 1
}
mono() { "$py" -c 'import time; print(f"{time.monotonic():.6f}")'; }
# kill_timed PID: SIGKILL, printing the monotonic times just before and just after (one process, so
# the two are microseconds apart, unlike two separate calls of mono around `kill`).
kill_timed() {
  "$py" -c 'import os, sys, time
t0 = time.monotonic(); os.kill(int(sys.argv[1]), 9); t1 = time.monotonic()
print(f"{t0:.6f} {t1:.6f}")' "$1"
}
# Prefixes each line of stdin with the monotonic time it arrived.
stamp_lines() {
  "$py" -u -c '
import sys, time
for line in iter(sys.stdin.readline, ""):
    sys.stdout.write(f"{time.monotonic():.6f} {line}")
    sys.stdout.flush()'
}
wait_for() {  # wait_for SECONDS COMMAND...: polls COMMAND every 50 ms
  local limit="$1"; shift
  local end=$((SECONDS + ${limit%.*} + 1))
  until "$@"; do
    [ "$SECONDS" -lt "$end" ] || return 1
    sleep 0.05
  done
}

# --- two network namespaces joined by a veth pair ---------------------------------------------------
# nsA holds the plant, nsB the controller; addresses 10.231.<domain>.1 and .2 exist only inside them.
nsA="qcs${domain}a"; nsB="qcs${domain}b"
ipA="10.231.$((domain % 256)).1"; ipB="10.231.$((domain % 256)).2"
make_namespaces() {
  local why=""
  if [ "$(id -u)" -ne 0 ]; then why="needs root (ip netns add), running as uid $(id -u)"
  elif ! command -v ip > /dev/null; then why="needs iproute2 (ip), not installed (scripts/install-deps.sh)"
  else
    # Leftovers of an earlier run under the same names (namespaces are torn down asynchronously).
    ip netns del "$nsA" 2>/dev/null || true
    ip netns del "$nsB" 2>/dev/null || true
    ip link del "$nsA" 2>/dev/null || true
    if ! { ip netns add "$nsA" && namespaces+=("$nsA") && ip netns add "$nsB" && namespaces+=("$nsB") &&
           ip link add "${nsA}" type veth peer name "${nsB}" &&
           ip link set "${nsA}" netns "$nsA" && ip link set "${nsB}" netns "$nsB" &&
           ip -n "$nsA" addr add "$ipA/24" dev "${nsA}" && ip -n "$nsB" addr add "$ipB/24" dev "${nsB}" &&
           ip -n "$nsA" link set "${nsA}" up && ip -n "$nsB" link set "${nsB}" up &&
           ip -n "$nsA" link set lo up && ip -n "$nsB" link set lo up; } > "$tmp/netns.log" 2>&1; then
      why="could not create network namespaces / veth: $(tr '\n' ' ' < "$tmp/netns.log")"
    fi
  fi
  if [ -n "$why" ]; then
    if [ "${QUADCOSIM_SKIP_NETNS:-0}" = 1 ]; then
      echo "SKIPPED [$case_name]: $why (QUADCOSIM_SKIP_NETNS=1)"
      exit 77
    fi
    fail "$why; set QUADCOSIM_SKIP_NETNS=1 to skip the network namespace tests"
  fi
}
in_ns() {  # in_ns NS ENV... -- COMMAND...: runs COMMAND inside NS with the DDS environment given
  local ns="$1"; shift
  ip netns exec "$ns" env -u ROS_STATIC_PEERS "$@"
}

# Lockstep paper altitude scenario: plant in nsA, controller in nsB, over real UDP on the veth pair.
# The trajectory and the recording must be byte-identical to the in-process run.
netns_identical() {
  local discovery_a=("$@")
  local s="$src/scenarios/paper/altitude_step.yaml"
  "$bin" run "$s" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
  make_namespaces
  mkdir -p "$tmp/ns"
  in_ns "$nsB" ROS_DOMAIN_ID="$domain" "${discovery_b[@]}" "$bin" controller --scenario "$s" --no-schedule \
    > "$tmp/controller.log" 2>&1 &
  pids+=($!)
  set +e
  in_ns "$nsA" ROS_DOMAIN_ID="$domain" "${discovery_a[@]}" timeout 100 "$bin" plant --scenario "$s" \
    --record "$tmp/ns/trajectory.csv" --mcap "$tmp/ns/run.mcap" --timeout 20 --schedule-via /attitude_controller \
    > "$tmp/plant.log" 2>&1
  local rc=$?
  set -e
  [ "$rc" -eq 0 ] || fail "plant across namespaces exited with $rc"
  cmp "$tmp/in/trajectory.csv" "$tmp/ns/trajectory.csv" || fail "trajectory differs from the in-process run"
  same_recording "$tmp/in/run.mcap" "$tmp/ns/run.mcap" || fail "MCAP recording differs from the in-process run"
  [ "$(wc -l < "$tmp/ns/trajectory.csv")" -eq 1502 ] || fail "trajectory has the wrong length"
  # One command per control tick (0, 0.02, ..., 15 s); repeats answering a tick asked for again are
  # counted as stale.
  local counts
  counts=$(sed -nE 's/.*commands received ([0-9]+), rejected 0, clamped 0, stale ([0-9]+).*/\1 \2/p' "$tmp/plant.log")
  [ -n "$counts" ] && [ $(( ${counts% *} - ${counts#* } )) -eq 751 ] || fail "unexpected command counts: $counts"
  echo "plant and controller in two network namespaces ($*): identical to in-process"
}

# --- nftables on the veth: loss, bursts and cuts on real UDP ------------------------------------------
# One table in nsA (the plant's side) filters both directions on its end of the veth pair: the input
# hook sees every datagram from the controller's namespace (commands, status, acknowledgements), the
# output hook every datagram to it (sensors, clock, heartbeats, retransmissions). Each datagram is
# counted (`seen`), dropped while chain `cut` holds a drop rule (counted as `cut`; empty unless the
# test fills it), and else dropped with LOSS % probability (chain `loss`, counted as `lost`).
nft_setup() {  # nft_setup LOSS_PERCENT: (re)creates the table; SKIPPED (77) when nftables cannot be used
  local loss="$1" rule="" why=""
  [ "$loss" -gt 0 ] && rule="numgen random mod 100 < $loss counter name \"lost\" drop;"
  if ! command -v nft > /dev/null; then
    why="needs nft (Debian package nftables, scripts/install-deps.sh), not installed"
  else
    ip netns exec "$nsA" nft delete table inet qcsfault 2>/dev/null || true
    if ! ip netns exec "$nsA" nft -f - > "$tmp/nft.log" 2>&1 <<EOF
table inet qcsfault {
  counter seen { }
  counter lost { }
  counter cut { }
  chain cut { }
  chain loss { $rule }
  chain input {
    type filter hook input priority filter; policy accept;
    iifname "$nsA" counter name "seen" jump cut
    iifname "$nsA" jump loss
  }
  chain output {
    type filter hook output priority filter; policy accept;
    oifname "$nsA" counter name "seen" jump cut
    oifname "$nsA" jump loss
  }
}
EOF
    then
      why="nftables refused the rules in a network namespace: $(tr '\n' ' ' < "$tmp/nft.log")"
    fi
  fi
  if [ -n "$why" ]; then
    echo "SKIPPED [$case_name]: $why"
    exit 77
  fi
}
nft_a() { ip netns exec "$nsA" nft "$@"; }
nft_count() { nft_a list counter inet qcsfault "$1" | grep -o 'packets [0-9]*' | grep -o '[0-9]*$'; }
# cut_timed on|off: fills or empties chain `cut`, printing the monotonic times just before and after.
cut_timed() {
  local args=(flush chain inet qcsfault cut)
  [ "$1" = on ] && args=(add rule inet qcsfault cut counter name '"cut"' drop)
  "$py" -c 'import subprocess, sys, time
t0 = time.monotonic(); subprocess.run(sys.argv[1:], check=True); t1 = time.monotonic()
print(f"{t0:.6f} {t1:.6f}")' ip netns exec "$nsA" nft "${args[@]}"
}
# altitude_scenario SECONDS: the paper altitude step, run for SECONDS, without its step criteria (made
# for 15 s); prints the file's path.
altitude_scenario() {
  local f="$tmp/altitude_$1.yaml"
  sed -e "s/^  duration_s: 15\$/  duration_s: $1/" -e '/^analysis:/,$d' "$src/scenarios/paper/altitude_step.yaml" > "$f"
  grep -q "^  duration_s: $1\$" "$f" || fail "could not set the duration in $f"
  echo "$f"
}
# nft_lockstep SCENARIO LOSS [FAULT]: lockstep across the namespaces (multicast discovery) through the
# rules above with LOSS % loss each way; FAULT, a function given the plant's pid, runs beside the
# plant. The trajectory must be byte-identical to the in-process run of the same scenario. Sets rtf
# (the plant's simulated/wall), rt_max_ms (its largest lockstep round trip) and the counters.
nft_lockstep() {
  local s="$1" loss="$2" fault="${3:-}" name
  name="$(basename "$s" .yaml)"
  if [ ! -f "$tmp/in_$name/trajectory.csv" ]; then
    "$bin" run "$s" --out "$tmp/in_$name" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
  fi
  [ "${#namespaces[@]}" -gt 0 ] || make_namespaces
  nft_setup "$loss"
  local env_ns=(ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET)
  rm -f "$tmp/ns.csv"
  in_ns "$nsB" "${env_ns[@]}" "$bin" controller --scenario "$s" --no-schedule > "$tmp/controller.log" 2>&1 &
  pids+=($!)
  in_ns "$nsA" "${env_ns[@]}" timeout 250 "$bin" plant --scenario "$s" --record "$tmp/ns.csv" --timeout 20 \
    --schedule-via /attitude_controller > "$tmp/plant.log" 2>&1 &
  local plant=$!; pids+=("$plant")
  [ -z "$fault" ] || "$fault" "$plant"
  set +e
  wait "$plant"; local rc=$?
  set -e
  stop_ns "$nsB"
  [ "$rc" -eq 0 ] || fail "plant across namespaces with $loss % loss exited with $rc"
  if ! cmp "$tmp/in_$name/trajectory.csv" "$tmp/ns.csv"; then
    first_difference "$tmp/in_$name/trajectory.csv" "$tmp/ns.csv"
    fail "trajectory with $loss % loss differs from the in-process run"
  fi
  rtf=$(sed -nE 's/.* simulated in [0-9.]+ s \(([0-9.]+)x real time\).*/\1/p' "$tmp/plant.log")
  rt_max_ms=$(sed -nE 's/.*lockstep round trip .* max ([0-9.]+) us.*/\1/p' "$tmp/plant.log")
  rt_max_ms=$("$py" -c "print(f'{$rt_max_ms / 1000:.1f}')")
  seen=$(nft_count seen); lost=$(nft_count lost); cut=$(nft_count cut)
  echo "lockstep $name, $loss % loss each way: identical to in-process; ${rtf}x real time, largest round trip" \
    "$rt_max_ms ms; datagrams on the veth $seen, lost $lost, cut $cut"
}
first_difference() {  # first_difference A.csv B.csv: the first rows that differ, column by column
  "$py" - "$1" "$2" <<'PY'
import csv, sys
a, b = list(csv.reader(open(sys.argv[1]))), list(csv.reader(open(sys.argv[2])))
print(f"rows: {len(a)} and {len(b)}")
shown = 0
for i, (x, y) in enumerate(zip(a, b)):
    if x != y and shown < 3:
        print(f"row {i}: " + ", ".join(f"{h} {u} / {v}" for h, u, v in zip(a[0], x, y) if u != v))
        shown += 1
PY
}
# stop_ns NS: ends every process in NS and waits until they are gone. $! of `in_ns ... &` is the
# subshell that runs the function, and ending it would leave its child running: a controller left
# over from one run answers the next one's plant on the same domain.
stop_ns() {
  local p
  for p in $(ip netns pids "$1"); do kill -TERM "$p" 2>/dev/null || true; done
  wait_for 10 bash -c "[ -z \"\$(ip netns pids '$1')\" ]" || {
    for p in $(ip netns pids "$1"); do kill -KILL "$p" 2>/dev/null || true; done
    wait_for 5 bash -c "[ -z \"\$(ip netns pids '$1')\" ]" || fail "processes in $1 outlived SIGKILL"
  }
}
# Waits until the plant has recorded SIZE bytes of trajectory: lockstep is under way.
wait_recording() { wait_for 60 bash -c "[ \$(stat -c %s '$tmp/ns.csv' 2>/dev/null || echo 0) -ge $1 ]"; }

case "$case_name" in
  controller_killed)  # real time: kill -9 the controller mid-hover, then start a new one
    limit=0.3  # tests/faults/hover.yaml: simulation.watchdog_s (policy hold)
    # A 0.3 s stale limit: on this loaded machine the plant's loop sometimes pauses for more than the
    # default 0.1 s (seen: 101 ms), and the stale-data safety (tested in plant_killed) would then stop
    # the rotors for a control period, which is not what this case is about.
    printf 'z_des: 1\nstale_limit: 0.3\n' > "$tmp/params.yaml"  # --params replaces the scenario's
    "$bin" controller --realtime --scenario "$hover" --params "$tmp/params.yaml" > "$tmp/c1.log" 2>&1 &
    c1=$!; pids+=("$c1")
    "$bin" plant --realtime --wait-for-controller --scenario "$hover" --duration 7 --record "$tmp/t.csv" \
      > "$tmp/plant.log" 2>&1 &
    plant=$!; pids+=("$plant")
    wait_for 15 grep -q "real-time mode" "$tmp/plant.log" || fail "plant did not start"
    wait_for 15 grep -q "controlling" "$tmp/c1.log" || fail "controller did not start controlling"
    sleep 2
    read -r k0 k1 < <(kill_timed "$c1")
    sleep 1
    "$bin" controller --realtime --scenario "$hover" --params "$tmp/params.yaml" > "$tmp/c2.log" 2>&1 &
    pids+=($!)
    set +e
    timeout 60 tail --pid="$plant" -f /dev/null
    wait "$plant"; rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    trip=$(grep "plant: watchdog: no valid motor command" "$tmp/plant.log" | head -1) || fail "no watchdog event logged"
    grep -q "plant: watchdog: valid motor commands again" "$tmp/plant.log" || fail "no release after the restart"
    grep -q "took over 1 times" "$tmp/plant.log" || fail "expected exactly one watchdog event"
    "$py" - "$tmp/t.csv" "$trip" "$k0" "$k1" "$limit" <<'PY' || fail "bounds (see above)"
import csv, re, sys
path, trip, k0, k1, limit = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
age = float(re.search(r"command for ([0-9.]+) s", trip).group(1))
t_trip = float(re.search(r"monotonic ([0-9.]+) s", trip).group(1))
tick, sched = 0.01, 0.04
# The plant acted within its limit: the age it saw at the trip, and the delay after the kill on the
# test's own clock (the last command left the controller at most one control period before k1).
print(f"watchdog: age at trip {age:.3f} s, {t_trip - k1:.3f}..{t_trip - k0:.3f} s after the kill (limit {limit} s)")
assert limit <= age <= limit + tick + sched, age
assert t_trip - k0 <= limit + tick + sched + 0.05, t_trip - k0
assert t_trip - k1 >= limit - 0.02 - tick - 0.005, t_trip - k1
rows = list(csv.DictReader(open(path)))
hover = 4830.6
cmd = [[float(r[f"cmd{i}"]) for i in range(1, 5)] for r in rows]
wd = [int(r["watchdog"]) for r in rows]
z = [float(r["z"]) for r in rows]
assert sum(wd) > 50, sum(wd)  # the outage is in the recording
release = max(k for k in range(1, len(wd)) if wd[k - 1] == 1 and wd[k] == 0)
jump = max(max(abs(a - b) for a, b in zip(cmd[k], cmd[k - 1])) for k in range(1, len(cmd)))
jump_restart = max(max(abs(a - b) for a, b in zip(cmd[k], cmd[k - 1])) for k in range(release, len(cmd)))
dz = max(abs(v - 1.0) for v in z)
print(f"restart at t = {rows[release]['t']} s: largest change between consecutive commands {jump_restart:.2f} rad/s "
      f"after it, {jump:.2f} rad/s over the run (hover {hover} rad/s); max |z - 1| {dz:.4f} m, final {z[-1]:.4f} m")
assert jump <= 0.02 * hover, jump
assert dz <= 0.05, dz
assert abs(z[-1] - 1.0) <= 0.02, z[-1]
PY
    ;;

  lockstep_hold)  # lockstep: the controller stops answering (SIGSTOP), the plant holds, then resumes
    "$bin" controller --scenario "$hover" > "$tmp/c.log" 2>&1 &
    ctl=$!; pids+=("$ctl")
    # 1200 s simulated: several seconds in lockstep, and seconds more than the pause below unpaced.
    "$bin" plant --scenario "$hover" --duration 1200 --timeout 1 --on-timeout hold --record "$tmp/t.csv" \
      > "$tmp/plant.log" 2>&1 &
    plant=$!; pids+=("$plant")
    wait_for 15 grep -q "lockstep mode" "$tmp/plant.log" || fail "plant did not start"
    sleep 0.3
    kill -STOP "$ctl"
    wait_for 10 grep -q "lockstep timeout" "$tmp/plant.log" || { kill -CONT "$ctl"; fail "no lockstep timeout"; }
    kill -CONT "$ctl"
    set +e
    timeout 60 tail --pid="$plant" -f /dev/null
    wait "$plant"; rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    grep -q "policy: hold" "$tmp/plant.log" || fail "the timeout did not name the hold policy"
    back=$(grep -o "commands are back at tick [0-9]*" "$tmp/plant.log" | grep -o "[0-9]*$") ||
      fail "lockstep did not resume"
    received=$(grep -o "commands received [0-9]*" "$tmp/plant.log" | grep -o "[0-9]*$")
    "$py" - "$tmp/t.csv" "$back" "$received" <<'PY' || fail "after the resume (see above)"
import csv, sys
path, back, received = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = list(csv.DictReader(open(path)))
last = len(rows) - 1  # ticks 0..120000
assert last == 120000, last
# After the resume every control tick is answered again: at least that many commands came in.
after = (last - back) // 2
print(f"resumed at tick {back}; {received} commands received, {after} control ticks after the resume")
assert back < last and received >= after, (back, received, after)
# And the controller flies the vehicle again: back at its 1 m hover at the end.
z = float(rows[-1]["z"])
assert abs(z - 1.0) < 0.05, z
PY
    ;;

  plant_killed)  # real time: kill -9 the plant; the controller's safety within its staleness limit
    limit=0.1  # the controller's stale_limit_s (default)
    "$bin" controller --realtime --scenario "$hover" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    mkfifo "$tmp/echo.fifo"  # two processes, both ended by the trap (a pipeline's $! is only its last)
    stamp_lines < "$tmp/echo.fifo" > "$tmp/status.txt" &
    pids+=($!)
    "$bin" topic echo /drone/controller_status --wait 10 > "$tmp/echo.fifo" 2> "$tmp/echo.log" &
    pids+=($!)
    "$bin" plant --realtime --scenario "$hover" --duration 60 > "$tmp/plant1.log" 2>&1 &
    p1=$!; pids+=("$p1")
    wait_for 15 bash -c "[ \$(grep -c 'safety: false' '$tmp/status.txt') -ge 50 ]" || fail "no normal control"
    read -r k0 k1 < <(kill_timed "$p1")
    sleep 1
    r0=$(mono)
    "$bin" plant --realtime --scenario "$hover" --duration 60 > "$tmp/plant2.log" 2>&1 &
    pids+=($!)
    wait_for 15 bash -c "awk '\$1 > $r0 && /safety: false/' '$tmp/status.txt' | grep -q ." || fail "no recovery"
    sleep 0.5
    grep -q "controller: stale sensor data: safety command" "$tmp/controller.log" || fail "no safety event logged"
    grep -q "controller: sensor data fresh again: normal control" "$tmp/controller.log" || fail "no recovery logged"
    "$py" - "$tmp/status.txt" "$k0" "$k1" "$r0" "$limit" <<'PY' || fail "bounds (see above)"
import sys
path, k0, k1, r0, limit = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
flags = [(float(l.split()[0]), l.split()[2] == "true") for l in open(path) if l.split()[1:2] == ["safety:"]]
period, sched = 0.02, 0.06
after_kill = [(t, s) for t, s in flags if t > k0]
first_safety = next(t for t, s in after_kill if s)
back = next(t for t, s in flags if t > r0 and not s)
during = [s for t, s in flags if first_safety <= t <= r0]
print(f"safety {first_safety - k1:.3f}..{first_safety - k0:.3f} s after the kill (limit {limit} s); "
      f"{len(during)} statuses during the outage, all safety; normal control {back - r0:.3f} s after the restart")
assert first_safety - k0 <= limit + period + sched, first_safety - k0
assert first_safety - k1 >= limit - 0.01 - 0.005, first_safety - k1
assert during and all(during)
assert back - r0 <= 10.0
PY
    ;;

  command_flood)  # thousands of commands per second from another participant: the plant keeps its rate
    "$bin" plant --realtime --scenario "$hover" --duration 5 --watchdog-policy hold > "$tmp/plant.log" 2>&1 &
    plant=$!; pids+=("$plant")
    # 20 000 commands/s: 200 per plant tick, 400 times the controller's rate; paced so the flood
    # measures the plant's loop, not how many cores the machine has left for it.
    "$flood" --seconds 4 --rate 20000 --count 200000 > "$tmp/flood.log" 2>&1 || fail "flood failed"
    set +e
    timeout 30 tail --pid="$plant" -f /dev/null
    wait "$plant"; rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    "$py" - "$tmp/flood.log" "$tmp/plant.log" <<'PY' || fail "bounds (see above)"
import re, sys
flood, plant = open(sys.argv[1]).read(), open(sys.argv[2]).read()
rate = float(re.search(r"\(([0-9.]+) per second\)", flood).group(1))
m = re.search(r"([0-9]+) ticks in ([0-9.]+) s wall \(([0-9.]+) ticks/s\), max lateness ([0-9.]+) ms, ([0-9]+) ticks more", plant)
ticks, wall, tps, late_ms, late = int(m.group(1)), float(m.group(2)), float(m.group(3)), float(m.group(4)), int(m.group(5))
received = int(re.search(r"commands received ([0-9]+)", plant).group(1))
print(f"flood {rate:.0f} commands/s; plant {tps:.1f} ticks/s, received {received}, max lateness {late_ms} ms, "
      f"{late} of {ticks} ticks more than a period late")
assert rate >= 10000, rate         # a real flood
assert received >= 10000, received # that reached the plant
assert 95.0 <= tps <= 105.0, tps   # 100 Hz kept
# On this shared 2-core machine some ticks come late with or without a flood (without: 0-10 of
# 501, up to 50 ms at load 8); the pacing is absolute, so they do not add up. A loop stalled by the
# flood (one that drained without bound) would fall behind for the whole 4 s of it.
assert late <= ticks // 4, late    # at most 25 % of ticks more than one period late
assert late_ms <= 500.0, late_ms   # and never half a second behind
PY
    ;;

  netns_multicast)  # discovery by multicast over the veth (ROS default range SUBNET)
    discovery_b=(ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET)
    netns_identical ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET
    ;;

  netns_static_peers)  # no multicast: unicast discovery to the other namespace's address
    discovery_b=(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_STATIC_PEERS="$ipA")
    netns_identical ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_STATIC_PEERS="$ipB"
    # Without the peers the two namespaces do not find each other: the peers are what connects them.
    in_ns "$nsB" ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST "$bin" controller \
      --namespace /lonely > "$tmp/controller2.log" 2>&1 &
    pids+=($!)
    set +e
    in_ns "$nsA" ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST timeout 30 "$bin" plant \
      --namespace /lonely --timeout 2 > "$tmp/plant2.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 4 ] || fail "without static peers the plant should find no controller (exit 4), got $rc"
    ;;

  netns_nft_loss10)  # lockstep through 0 %, then 10 % loss each way (nftables): identical; the speed lost
    s=$(altitude_scenario 15)
    nft_lockstep "$s" 0
    rtf0=$rtf
    [ "$lost" -eq 0 ] && [ "$cut" -eq 0 ] || fail "datagrams dropped without loss: lost $lost, cut $cut"
    nft_lockstep "$s" 10
    "$py" - "$seen" "$lost" "$rtf0" "$rtf" <<'PY' || fail "loss rate (see above)"
import sys
seen, lost, rtf0, rtf = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
# Binomial: with n >= 3000 datagrams the standard deviation of the loss fraction is <= 0.55 %.
print(f"10 % loss: {lost} of {seen} datagrams dropped ({100 * lost / seen:.1f} %); "
      f"{rtf0}x real time without loss, {rtf}x with it")
assert seen >= 3000, seen
assert 0.07 <= lost / seen <= 0.13, lost / seen
PY
    ;;

  netns_nft_loss30)  # lockstep through 30 % loss each way: identical (5 s of the step: it runs below real time)
    nft_lockstep "$(altitude_scenario 5)" 30
    "$py" - "$seen" "$lost" <<'PY' || fail "loss rate (see above)"
import sys
seen, lost = int(sys.argv[1]), int(sys.argv[2])
print(f"30 % loss: {lost} of {seen} datagrams dropped ({100 * lost / seen:.1f} %)")
assert seen >= 1000, seen
assert 0.25 <= lost / seen <= 0.35, lost / seen
PY
    ;;

  netns_nft_bursts)  # lockstep while the link drops everything for 200 ms of every second
    bursts() {  # from when lockstep is under way until the plant ends
      local plant="$1" n=0
      wait_recording 100000 || fail "lockstep did not start"
      while kill -0 "$plant" 2>/dev/null; do
        cut_timed on > /dev/null
        sleep 0.2
        cut_timed off > /dev/null
        n=$((n + 1))
        sleep 0.8
      done
      echo "$n" > "$tmp/bursts"
    }
    nft_lockstep "$(altitude_scenario 900)" 0 bursts  # 900 s: several seconds even at 250x
    n=$(cat "$tmp/bursts")
    echo "$n bursts of 200 ms during the run"
    [ "$n" -ge 3 ] || fail "only $n bursts while lockstep ran"
    [ "$cut" -gt 0 ] || fail "the bursts dropped nothing"
    ;;

  netns_nft_cut)  # lockstep while the link is cut for 2 s, then healed
    cut_2s() {
      wait_recording 100000 || fail "lockstep did not start"
      cut_timed on > "$tmp/cut_on"
      sleep 2
      cut_timed off > "$tmp/cut_off"
      kill -0 "$1" 2>/dev/null || fail "the plant ended before the link was healed: cut too late"
    }
    nft_lockstep "$(altitude_scenario 600)" 0 cut_2s
    ! grep -q "lockstep timeout" "$tmp/plant.log" || fail "a lockstep timeout during a 2 s cut (--timeout 20)"
    "$py" - "$rt_max_ms" "$cut" <<'PY' || fail "the cut was not felt (see above)"
import sys
rt_max_ms, cut = float(sys.argv[1]), int(sys.argv[2])
print(f"2 s cut: {cut} datagrams dropped; the longest lockstep round trip {rt_max_ms:.0f} ms")
assert cut > 0, cut
assert rt_max_ms >= 1900, rt_max_ms  # a round trip spanned the cut: lockstep waited it out
PY
    ;;

  netns_nft_hover_rt)  # real time, position hold in gusts through 10 % loss each way: within the bounds
    s="$tmp/hover_gusts_15.yaml"
    sed 's/^  duration_s: 30$/  duration_s: 15/' "$src/tests/faults/hover_gusts.yaml" > "$s"
    "$bin" run "$s" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
    make_namespaces
    nft_setup 10
    env_ns=(ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET)
    in_ns "$nsB" "${env_ns[@]}" "$bin" controller --realtime --scenario "$s" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    set +e
    in_ns "$nsA" "${env_ns[@]}" timeout 60 "$bin" plant --realtime --wait-for-controller --timeout 20 \
      --scenario "$s" --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    "$py" - "$tmp/t.csv" "$tmp/in/trajectory.csv" "$(nft_count seen)" "$(nft_count lost)" "$tmp/controller.log" \
      <<'PY' || fail "hover under 10 % loss (see above)"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
# The controller's own count of stale-data episodes: the plant records the safety flag from the
# statuses it receives, and 10 % of those are lost too (a one-period episode can go unrecorded).
episodes = open(sys.argv[5]).read().count("stale sensor data: safety command")
ref = {r["t"]: float(r["z"]) for r in csv.DictReader(open(sys.argv[2]))}
seen, lost = int(sys.argv[3]), int(sys.argv[4])
e = [float(r["z"]) - 1.0 for r in rows]
dev = [abs(float(r["z"]) - ref[r["t"]]) for r in rows]
safety = sum(int(r["safety"]) for r in rows)
wd = sum(int(r["watchdog"]) for r in rows)
rms = math.sqrt(sum(v * v for v in e) / len(e))
ref_e = [v - 1.0 for v in ref.values()]
ref_max = max(map(abs, ref_e))
ref_rms = math.sqrt(sum(v * v for v in ref_e) / len(ref_e))
n = max(safety // 2, episodes)  # control periods on the stale-data safety command (2 plant ticks each)
print(f"real-time hover in gusts, 10 % loss ({lost} of {seen} datagrams): |z - 1| max {max(map(abs, e)):.4f} m, "
      f"RMS {rms:.4f} m (in-process: max {ref_max:.4f}, RMS {ref_rms:.4f}); |z - z_in-process| max {max(dev):.4f} m; "
      f"{n} control periods on the safety command, watchdog ticks {wd}")
assert len(rows) == 1501, len(rows)
assert 0.07 <= lost / seen <= 0.13, lost / seen
# Measured (13 runs): without a safety period the flight is the in-process one to within 1 cm; a
# retransmission later than stale_limit (0.1 s) puts the controller on its safety command (rotors
# stopped) for a control period, which moved the vehicle up to 11.4 cm from the in-process flight
# (|z - 1| max +8 cm, RMS +2.4 cm). 0-1 such periods per run were seen; the bounds allow 3, each with
# a margin.
assert n <= 3, n
assert max(map(abs, e)) <= ref_max + 0.03 + 0.15 * n, max(map(abs, e))
assert rms <= ref_rms + 0.01 + 0.04 * n, rms
assert max(dev) <= 0.03 + 0.15 * n, max(dev)
assert wd == 0, wd
PY
    ;;

  netns_nft_cut_rt)  # real time: a 2 s cut; the watchdog and the stale-data safety act, both recover
    wd_limit=0.3 stale_limit=0.1  # hover.yaml simulation.watchdog_s (policy hold); the controller's default
    # The trimmed hover, which the held command keeps (a held command of a vehicle in gusts or with
    # noisy sensors tips it over within the 2 s: measured), and a step to 1.5 m at 8 s, after the
    # heal, which only a controller in command flies.
    s="$tmp/hover_step.yaml"
    { sed 's/^  duration_s: 30$/  duration_s: 12/' "$src/tests/faults/hover.yaml"
      printf 'schedule:\n  - at_s: 8\n    set: {z_des: 1.5}\n'; } > "$s"
    "$bin" run "$s" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
    make_namespaces
    nft_setup 0
    env_ns=(ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET)
    in_ns "$nsB" "${env_ns[@]}" "$bin" controller --realtime --scenario "$s" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    in_ns "$nsA" "${env_ns[@]}" "$bin" plant --realtime --wait-for-controller --timeout 20 --scenario "$s" \
      --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1 &
    plant=$!; pids+=("$plant")
    wait_for 25 grep -q "real-time mode" "$tmp/plant.log" || fail "plant did not start"
    wait_for 15 grep -q "controlling" "$tmp/controller.log" || fail "controller did not start controlling"
    sleep 2
    read -r c0 c1 < <(cut_timed on)
    sleep 2
    read -r h0 h1 < <(cut_timed off)
    set +e
    timeout 60 tail --pid="$plant" -f /dev/null
    wait "$plant"; rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    grep -q "took over 1 times" "$tmp/plant.log" || fail "expected exactly one watchdog event"
    trip=$(grep "plant: watchdog: no valid motor command" "$tmp/plant.log") || fail "no watchdog event logged"
    release=$(grep "plant: watchdog: valid motor commands again" "$tmp/plant.log") || fail "no release after the heal"
    stale=$(grep "controller: stale sensor data" "$tmp/controller.log" | head -1) || fail "no safety event logged"
    fresh=$(grep "controller: sensor data fresh again" "$tmp/controller.log" | head -1) || fail "no recovery logged"
    "$py" - "$tmp/t.csv" "$tmp/in/trajectory.csv" "$trip" "$release" "$stale" "$fresh" "$c0" "$c1" "$h0" "$h1" \
      "$wd_limit" "$stale_limit" "$(nft_count cut)" <<'PY' || fail "bounds (see above)"
import csv, re, sys
path, ref_path, trip, release, stale, fresh = sys.argv[1:7]
c0, c1, h0, h1, wd_limit, stale_limit = map(float, sys.argv[7:13])
cut = int(sys.argv[13])
mono = lambda line: float(re.search(r"monotonic ([0-9.]+) s", line).group(1))
t_trip, t_release, t_stale, t_fresh = mono(trip), mono(release), mono(stale), mono(fresh)
wd_age = float(re.search(r"command for ([0-9.]+) s", trip).group(1))
stale_age = float(re.search(r"data age ([0-9.]+) s", stale).group(1))
tick, period, sched = 0.01, 0.02, 0.06
print(f"2 s cut ({cut} datagrams dropped) set at monotonic {c0:.3f}..{c1:.3f} (nft ran in between), "
      f"healed {h0:.3f}..{h1:.3f}")
print(f"plant watchdog: age at trip {wd_age:.3f} s (limit {wd_limit} s), {t_trip - c1:.3f}..{t_trip - c0:.3f} s "
      f"after the cut; released {t_release - h1:.3f}..{t_release - h0:.3f} s after the heal")
print(f"controller safety: age {stale_age:.3f} s (limit {stale_limit} s), {t_stale - c1:.3f}..{t_stale - c0:.3f} s "
      f"after the cut; normal control {t_fresh - h1:.3f}..{t_fresh - h0:.3f} s after the heal")
# Each acted within its limit: the age it saw, and the time after the cut on the test's clock. The cut
# took effect between c0 and c1; the last datagram before it crossed at most a control period (the
# plant's commands) or a plant tick (the controller's samples) earlier; each checks the age once per
# its own period, late by scheduling at most `sched`.
assert wd_limit <= wd_age <= wd_limit + tick + sched, wd_age
assert t_trip - c0 >= wd_limit - period - 0.005, t_trip - c0
assert t_trip - c1 <= wd_limit + tick + sched, t_trip - c1
assert stale_limit <= stale_age <= stale_limit + period + sched, stale_age
assert t_stale - c0 >= stale_limit - tick - 0.005, t_stale - c0
assert t_stale - c1 <= stale_limit + period + sched, t_stale - c1
# Both acted during the cut and let go after the heal, within a second.
assert t_trip < h0 and t_stale < h0, (t_trip, t_stale)
assert h0 < t_release <= h1 + 1.0 and h0 < t_fresh <= h1 + 1.0, (t_release, t_fresh)
rows = list(csv.DictReader(open(path)))
ref = list(csv.DictReader(open(ref_path)))
assert len(rows) == len(ref) == 1201, (len(rows), len(ref))
wd = [int(r["watchdog"]) for r in rows]
z = [float(r["z"]) for r in rows]
zr = [float(r["z"]) for r in ref]
k_rel = max(k for k in range(1, len(wd)) if wd[k - 1] == 1 and wd[k] == 0)
held = sum(wd)
# The hold lasts the cut less the limit, to within the nft windows and a control period or two.
assert h0 - c1 - wd_limit - 0.1 <= held * tick <= h1 - c0 - wd_limit + 0.2, held
assert not any(wd[k_rel:]), "the watchdog acted again after the release"
assert k_rel < 750, k_rel  # released before the step at 8 s
# The first commands across the healed link are the controller's safety commands (safety: stop, the
# default: rotors at 0), sent until fresh samples reach it; then its control resumes.
stops = next(k for k in range(k_rel, len(rows)) if float(rows[k]["cmd1"]) > 0) - k_rel
low = min(z[k_rel:800])
k_low = k_rel + z[k_rel:800].index(low)
print(f"released at t = {rows[k_rel]['t']} s after {held} held ticks; then {stops} ticks of the safety command "
      f"(stopped rotors) and control again: lowest z {low:.3f} m at t = {rows[k_low]['t']} s, "
      f"{z[799]:.3f} m at 8 s; step to 1.5 m at 8 s: z at 12 s {z[-1]:.3f} m (in-process {zr[-1]:.3f})")
assert max(abs(v - 1.0) for v in z[:k_rel]) <= 0.005, "the held trim command kept the hover until the release"
assert stops * tick <= 0.2, stops
assert low >= 0.6, low  # a fall of g for 0.2 s (the stops) and the time the climb back takes
if low < 0.98:  # climbing back under control before the step: measured 58-100 % of the drop regained
    assert z[799] - low >= 0.4 * (1.0 - low), z[799]
assert z[-1] - z[799] >= 0.3, z[-1]  # and flying the step: the in-process one climbs 0.5 m
PY
    ;;

  soak_rss)  # a long recorded lockstep run: neither process's resident set grows after warm-up
    # One simulated hour (18-100 s here at 40-200x real time), localhost in the test's namespace,
    # sampled every 0.25 s (every second gave too few samples on a fast machine). The plant records
    # the CSV and run.mcap as `run --transport dds` does (bench/soak.sh): with every chunk's index
    # held in memory it grew by 3.3 MB per simulated hour, 2.5 MB in the quarters compared here.
    ROS_DOMAIN_ID="$domain" bash "$src/bench/soak.sh" "$bin" 3600 "$tmp/soak.json" 0.25 > "$tmp/soak.log" 2>&1 ||
      fail "soak run failed: $(cat "$tmp/soak.log")"
    grep "^soak: " "$tmp/soak.log"
    "$py" - "$tmp/soak.json" <<'PY' || fail "resident set growth (see above)"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["simulated_s"] == 3600, s["simulated_s"]
assert s["samples"] >= 20, s["samples"]  # at least 5 samples per quarter
outputs = s["outputs_bytes"]
print(f"recorded: {outputs}")
assert outputs.get("trajectory.csv", 0) > 100e6 and outputs.get("run.mcap", 0) > 100e6, outputs  # it recorded
plant, controller = s["plant"], s["controller"]
print(f"growth first -> last quarter: plant {plant['growth_kB']} kB, controller {controller['growth_kB']} kB")
# Growth is the median of the last quarter's samples less the median of the first's (warm-up). The
# lockstep round trips are kept in a fixed-size histogram (analysis/log_histogram.hpp) and the MCAP
# chunk indexes beyond 64 KiB in a spill file (io/mcap_writer.hpp), so nothing may grow with the
# run's length: at most 0.5 MB each (a leak of one 100-byte allocation per control tick would add
# 13 MB; keeping every round trip, as the plant once did, 1 MB; every chunk index, 2.5 MB).
assert plant["growth_kB"] <= 512, plant["growth_kB"]
assert controller["growth_kB"] <= 512, controller["growth_kB"]
PY
    ;;

  limits)  # sane limits: each refusal exit 2 naming the key and the limit, each overridable
    expect_refusal() {  # expect_refusal WHAT TEXT... -- COMMAND...: exit 2 and every TEXT in the message
      local what="$1"; shift
      local texts=()
      while [ "$1" != "--" ]; do texts+=("$1"); shift; done
      shift
      set +e
      /usr/bin/time -f "max_rss_kb %M" "$@" > "$tmp/limit.log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -eq 2 ] || fail "$what: expected exit 2, got $rc: $(tail -3 "$tmp/limit.log")"
      local t
      for t in "${texts[@]}"; do
        grep -qF -- "$t" "$tmp/limit.log" || fail "$what: message lacks '$t': $(cat "$tmp/limit.log")"
      done
      echo "$what: $(grep -m1 'error' "$tmp/limit.log" | cut -c1-220) [$(grep max_rss_kb "$tmp/limit.log")]"
    }
    run_ok() {  # run_ok WHAT COMMAND...
      local what="$1"; shift
      "$@" > "$tmp/ok.log" 2>&1 || fail "$what: exit $?: $(tail -3 "$tmp/ok.log")"
      echo "$what: accepted"
    }
    scen() { printf 'simulation: {plant_rate_hz: %s, controller_rate_hz: 50, duration_s: %s}\n' "$1" "$2"; }
    # A plant at a megahertz, and at 20 kHz: refused by default, the latter flown with the limit raised.
    scen 1e6 0.1 > "$tmp/fast.yaml"
    expect_refusal "plant at 1 MHz" "simulation.plant_rate_hz: got 1e+06 Hz, more than the limit of 10000 Hz" \
      "--limit plant_rate_hz=N" "--no-limits" -- "$bin" run "$tmp/fast.yaml" --out "$tmp/fast" --no-plots
    scen 2e4 0.1 > "$tmp/fast.yaml"
    expect_refusal "plant at 20 kHz" "simulation.plant_rate_hz: got 20000 Hz, more than the limit of 10000 Hz" -- \
      "$bin" run "$tmp/fast.yaml" --out "$tmp/fast" --no-plots
    run_ok "plant at 20 kHz with --limit plant_rate_hz=2e4" \
      "$bin" run "$tmp/fast.yaml" --out "$tmp/fast" --no-plots --limit plant_rate_hz=2e4
    # run --transport dds hands the raised limit to its plant and controller processes.
    run_ok "plant at 20 kHz over DDS with --limit plant_rate_hz=2e4" \
      "$bin" run "$tmp/fast.yaml" --out "$tmp/fast_dds" --no-plots --transport dds --limit plant_rate_hz=2e4
    # 1e7 s: about 500 GB of outputs projected against the free disk of --out, both named.
    scen 100 1e7 > "$tmp/long.yaml"
    expect_refusal "1e7 s run" "the outputs would need about" "free on the disk of $tmp/long" -- \
      "$bin" run "$tmp/long.yaml" --out "$tmp/long" --no-plots
    [ ! -e "$tmp/long" ] || fail "1e7 s run: the refused run created its output folder"
    # A 94 MB scenario of 2 M schedule entries: refused by its size before it is parsed (small RSS).
    python3 - "$tmp" <<'PY'
import sys
tmp = sys.argv[1]
def write(name, entries, key="mode", value="attitude"):
    with open(f"{tmp}/{name}", "w") as f:
        f.write("simulation: {duration_s: 1}\nschedule:\n")
        line = f"  - {{at_s: 0.5, set: {{{key}: {value}}}}}\n"
        f.write(line * entries)
write("huge.yaml", 2_000_000, "altitude.kp", "12.000000")  # 94 MB
write("long_schedule.yaml", 20_001)  # 0.8 MB
write("eleven.yaml", 11)
PY
    size=$(stat -c %s "$tmp/huge.yaml")
    expect_refusal "94 MB scenario" "the file is $size bytes, more than the 2097152 a scenario file may have" \
      "limit scenario_bytes" -- "$bin" run "$tmp/huge.yaml" --out "$tmp/huge" --no-plots
    rss=$(sed -n 's/max_rss_kb //p' "$tmp/limit.log")
    [ "$rss" -lt 100000 ] || fail "94 MB scenario: the refusal took $rss kB (parsed before refusing?)"
    expect_refusal "20,001 schedule entries" "schedule: 20001 entries, more than the limit of 20000" -- \
      "$bin" run "$tmp/long_schedule.yaml" --out "$tmp/ls" --no-plots
    expect_refusal "11 schedule entries under a limit of 10" "schedule: 11 entries, more than the limit of 10" -- \
      "$bin" run "$tmp/eleven.yaml" --out "$tmp/e" --no-plots --limit schedule_entries=10
    run_ok "11 schedule entries under the default" "$bin" run "$tmp/eleven.yaml" --out "$tmp/e" --no-plots
    expect_refusal "an unknown limit" "--limit nope=1: expected NAME=VALUE with NAME one of scenario_bytes" -- \
      "$bin" run "$tmp/eleven.yaml" --out "$tmp/e2" --no-plots --limit nope=1
    # A swarm beyond the memory: 10 M vehicles at about 40 kB each against MemAvailable.
    expect_refusal "10 M vehicles" "--vehicles 10000000: the swarm would need about" "available (MemAvailable)" -- \
      "$bin" run "$hover" --out "$tmp/swarm" --no-plots --vehicles 10000000
    # FMUs: 200,000 variables, 10,001 entries, and an archive that unpacks beyond the bound.
    python3 - "$tmp" <<'PY'
import sys, zipfile
tmp = sys.argv[1]
def md(n):
    v = "".join(f'<ScalarVariable name="v{i}" valueReference="{i}"><Real/></ScalarVariable>' for i in range(n))
    return ('<?xml version="1.0"?><fmiModelDescription fmiVersion="2.0" modelName="m" guid="g">'
            '<CoSimulation modelIdentifier="m"/><ModelVariables>' + v + '</ModelVariables></fmiModelDescription>')
with zipfile.ZipFile(f"{tmp}/vars.fmu", "w", zipfile.ZIP_DEFLATED) as z:
    z.writestr("modelDescription.xml", md(200_000))
with zipfile.ZipFile(f"{tmp}/entries.fmu", "w") as z:
    z.writestr("modelDescription.xml", md(1))
    for i in range(10_001):
        z.writestr(f"resources/f{i}", "")
with zipfile.ZipFile(f"{tmp}/bomb.fmu", "w", zipfile.ZIP_DEFLATED) as z:
    z.writestr("modelDescription.xml", md(1))
    z.writestr("resources/zeros", b"\0" * (8 << 20))  # 8 MiB, 8 kB packed
for name in ("vars", "entries", "bomb"):
    open(f"{tmp}/{name}.yaml", "w").write(f"simulation: {{duration_s: 1}}\nplant: {{fmu: {name}.fmu}}\n")
PY
    expect_refusal "FMU of 200,000 variables" "ModelVariables lists 200000 variables, more than the 100000" \
      "limit fmu_variables" -- "$bin" run "$tmp/vars.yaml" --out "$tmp/v" --no-plots
    expect_refusal "FMU of 10,002 entries" "the archive has 10002 entries, more than the 10000" -- \
      "$bin" run "$tmp/entries.yaml" --out "$tmp/en" --no-plots
    expect_refusal "FMU unpacking to 8 MiB under a limit of 4 MB" "unpack to more than 4000000 bytes" \
      "limit fmu_unpacked_bytes" -- "$bin" run "$tmp/bomb.yaml" --out "$tmp/b" --no-plots --limit fmu_unpacked_bytes=4e6
    ;;

  netns_netem)  # 10 % loss and 5 ms delay on the veth (tc netem), real-time hover across namespaces
    make_namespaces
    if ! ip netns exec "$nsA" tc qdisc add dev "$nsA" root netem loss 10% delay 5ms > "$tmp/tc.log" 2>&1; then
      echo "SKIPPED [$case_name]: this kernel refuses tc netem ($(tr '\n' ' ' < "$tmp/tc.log")); delay over the"
      echo "network is not tested here. Loss, bursts and cuts on the same veth are, with nftables"
      echo "(faults.netns_nft_*); the in-process fault injection delays too (sim_test FaultInjectionTest.*)."
      exit 77
    fi
    ip netns exec "$nsB" tc qdisc add dev "$nsB" root netem loss 10% delay 5ms || fail "netem on $nsB"
    env_ns=(ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET)
    in_ns "$nsB" "${env_ns[@]}" "$bin" controller --realtime --scenario "$hover" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    set +e
    in_ns "$nsA" "${env_ns[@]}" timeout 60 "$bin" plant --realtime --wait-for-controller --timeout 20 \
      --scenario "$hover" --duration 8 --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 0 ] || fail "plant exited with $rc"
    "$py" - "$tmp/t.csv" <<'PY' || fail "hover under netem (see above)"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
dz = max(abs(float(r["z"]) - 1.0) for r in rows)
wd = sum(int(r["watchdog"]) for r in rows)
print(f"hover across namespaces under netem loss 10 % delay 5 ms: max |z - 1| {dz:.4f} m, watchdog ticks {wd}")
assert dz <= 0.05, dz
assert wd == 0, wd
PY
    ;;

  bad_input)  # the new flags and keys refuse what they cannot do, naming it, with exit 2
    expect_2() {  # expect_2 WHAT TEXT COMMAND...
      local what="$1" text="$2"; shift 2
      set +e
      "$@" > "$tmp/bad.log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -eq 2 ] || fail "$what: expected exit 2, got $rc"
      grep -q -- "$text" "$tmp/bad.log" || fail "$what: message lacks '$text': $(cat "$tmp/bad.log")"
    }
    expect_2 "--watchdog off the tick grid" "--watchdog 0.015: expected a whole number of plant periods" \
      "$bin" plant --watchdog 0.015
    printf 'simulation: {duration_s: 1}\nmessage_faults: {drop_probability: 0.1}\n' > "$tmp/lossy.yaml"
    expect_2 "faults over DDS (run)" "injected by the in-process transport only" \
      "$bin" run "$tmp/lossy.yaml" --out "$tmp/r" --no-plots --transport dds
    expect_2 "faults over DDS (plant)" "message_faults: message loss and delay are injected by the in-process" \
      "$bin" plant --scenario "$tmp/lossy.yaml"
    expect_2 "faults over DDS (controller)" "message_faults: message loss and delay are injected by the in-process" \
      "$bin" controller --scenario "$tmp/lossy.yaml"
    printf 'simulation: {watchdog_policy: land}\n' > "$tmp/policy.yaml"
    expect_2 "unknown policy in a scenario" "simulation.watchdog_policy" "$bin" plant --scenario "$tmp/policy.yaml"
    # In-process the same scenario runs, and says what the faults did.
    "$bin" run "$tmp/lossy.yaml" --out "$tmp/r" --no-plots > "$tmp/run.log" 2>&1 || fail "in-process run with faults"
    grep -q "injected faults dropped: [0-9]* motor commands" "$tmp/run.log" || fail "no fault counts printed"
    ;;

  *) fail "unknown case" ;;
esac
echo "PASS [$case_name]"
