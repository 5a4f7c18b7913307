#!/usr/bin/env bash
# Faults with real processes, and plant and controller in two network namespaces.
# Usage: faults_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FLOOD_BINARY
# Each case runs on its own ROS_DOMAIN_ID and ends every process it started (trap), also on failure,
# including the processes inside network namespaces and the namespaces themselves.
# Times are compared on the monotonic clock (CLOCK_MONOTONIC: the nodes' steady clock and Python's
# time.monotonic()). Bounds and why they are what they are: docs/reliability.md.
# The netns cases need root and iproute2. When namespaces cannot be created they fail, unless
# QUADCOSIM_SKIP_NETNS=1, which makes them report SKIPPED (exit 77).
set -euo pipefail
bin="$1"; src="$2"; case_name="$3"; domain="$4"; flood="${5:-}"
export ROS_DOMAIN_ID="$domain" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
py=/usr/bin/python3
hover="$src/tests/faults/hover.yaml"
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
  cmp "$tmp/in/run.mcap" "$tmp/ns/run.mcap" || fail "MCAP recording differs from the in-process run"
  [ "$(wc -l < "$tmp/ns/trajectory.csv")" -eq 1502 ] || fail "trajectory has the wrong length"
  # One command per control tick (0, 0.02, ..., 15 s); repeats answering a tick asked for again are
  # counted as stale.
  local counts
  counts=$(sed -nE 's/.*commands received ([0-9]+), rejected 0, clamped 0, stale ([0-9]+).*/\1 \2/p' "$tmp/plant.log")
  [ -n "$counts" ] && [ $(( ${counts% *} - ${counts#* } )) -eq 751 ] || fail "unexpected command counts: $counts"
  echo "plant and controller in two network namespaces ($*): identical to in-process"
}

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

  netns_netem)  # 10 % loss and 5 ms delay on the veth (tc netem), real-time hover across namespaces
    make_namespaces
    if ! ip netns exec "$nsA" tc qdisc add dev "$nsA" root netem loss 10% delay 5ms > "$tmp/tc.log" 2>&1; then
      echo "SKIPPED [$case_name]: this kernel refuses tc netem ($(tr '\n' ' ' < "$tmp/tc.log")); message loss and"
      echo "delay over the network are not tested here. The in-process fault injection is (sim_test"
      echo "FaultInjectionTest.*), and two-namespace lockstep runs in faults.netns_multicast/static_peers."
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
