#!/usr/bin/env bash
# Betaflight in the loop (docs/sitl.md, "Betaflight"): the test Betaflight (tests/sitl/fake_betaflight.cpp)
# flown through `quadcosim run` and checked against closed forms and its record of what it received; the
# refusals (a second instance on the fixed ports, a silent firmware, a bad section); and the real SITL
# build named by QUADCOSIM_BETAFLIGHT_SITL (real_betaflight, SKIPPED without it).
# Usage: betaflight_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FAKE_FIRMWARE
bin="$1"; src="$2"; fake_bf="$(dirname "$5")/fake_betaflight"
# shellcheck source=../lib/process_case.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
here="$src/tests/sitl"
py=/usr/bin/python3
bf_cleanup() {
  local f
  set +e
  for f in "$tmp"/*.pid; do [ -f "$f" ] && { kill -KILL "$(cat "$f")" 2>/dev/null || true; }; done
}
trap 'bf_cleanup; cleanup' EXIT
# scenario NAME [ARG...]: the hover scenario flying the built test Betaflight with ARGs, as $tmp/NAME.yaml.
scenario() {
  local name="$1"; shift
  local args=""
  for a in "$@"; do args="$args\"$a\", "; done
  sed -e "s|binary: fake_betaflight.*|binary: $fake_bf|" \
      -e "s|    timeout_s: 2|    timeout_s: 2\n    args: [${args%, }]|" "$here/fake_betaflight_hover.yaml" > "$tmp/$name.yaml"
}
run() {  # run NAME EXPECTED_RC
  local name="$1" want="$2" rc=0
  "$bin" run "$tmp/$name.yaml" --out "$tmp/$name" --judge none > "$tmp/$name.log" 2>&1 || rc=$?
  [ "$rc" -eq "$want" ] || fail "$name exited $rc, expected $want"
}
gone() {
  local pid; pid="$(cat "$1")"
  ! kill -0 "$pid" 2>/dev/null || fail "firmware $pid still runs after the run"
}

case "$case_name" in
  bf_hover)
    # Disarmed until 1 s (rotors stopped, on the ground), then idling, then 2 m held within 5 cm at 12 s, exactly
    # level (the test Betaflight's PD sees no error), the rotors at the closed-form hover speed
    # sqrt(m g / 4 k_t) = 4830.6 rad/s within 1 %, each rotor's speed its motor's value times
    # omega_max (rotor 1 <- motor 4, 2 <- 2, 3 <- 1, 4 <- 3), and what reached it in its frames.
    scenario hv --fake-pid-file "$tmp/hv.pid" --fake-record "$tmp/hv.rec"
    run hv 0
    gone "$tmp/hv.pid"
    "$py" - "$tmp/hv/trajectory.csv" "$tmp/hv.rec" <<'PY' || fail "hover"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 4801, len(rows)
before = [r for r in rows if float(r["t"]) < 1.0 - 1e-9]
assert all(float(r[f"w{i}"]) == 0 for r in before for i in range(1, 5)), "a rotor turned before arming"
assert all(r["out.arm"] == "0" and float(r["z"]) == 0 for r in before)
assert all(r["out.arm"] == "1" for r in rows if float(r["t"]) >= 1.0 - 1e-9)
z = float(rows[-1]["z"])
assert abs(z - 2.0) < 0.05, f"z(12 s) = {z}"
assert max(abs(float(r["roll"])) + abs(float(r["pitch"])) for r in rows) < 1e-9
tail = [r for r in rows if float(r["t"]) >= 10.0]
mean_w = sum(sum(float(r[f"w{i}"]) for i in range(1, 5)) / 4 for r in tail) / len(tail)
hover = math.sqrt(1.96 * 9.81 / (4 * 2.06e-7))
assert abs(mean_w / hover - 1) < 0.01, (mean_w, hover)
for r in rows[::97]:
    for rotor, motor in ((1, 4), (2, 2), (3, 1), (4, 3)):
        want = float(r[f"out.m{motor}"]) * 12000.0
        assert abs(float(r[f"cmd{rotor}"]) - want) <= 1e-6 * max(1.0, want), (r["t"], rotor, r[f"cmd{rotor}"], want)
rec = [list(map(float, line.split())) for line in open(sys.argv[2])]
# The prelude (the initial state stamped 0 and 2.5 ms), then step k stamped t_k + 5 ms.
assert [x[0] for x in rec[:2]] == [0.0, 0.0025] and rec[0][1:] == rec[2][1:], rec[:3]
first = rec[2]
# t, gyro FRD, accel FRD (at rest on the ground: -9.81 along down), velocity ENU, lon/lat/alt, quat, pressure,
# RC channels 1..5.
assert first[0] == 0.005 and first[4:7] == [0.0, 0.0, -9.81], first[:7]
assert first[10:13] == [0.0, 0.0, 0.0], first[10:13]  # longitude, latitude, altitude of the site's origin
assert first[13:17] == [1.0, 0.0, 0.0, 0.0] and first[17] == 101325.0, first[13:18]
assert first[18:23] == [1500, 1500, 1000, 1500, 1000], first[18:23]
steps = rec[2:]
armed_rc = [x for x in steps if x[0] >= 1.005 - 1e-9]
assert armed_rc and all(x[22] == 2000 for x in armed_rc)
# Its motors idle from its answer at 1 s: seen at 1.0025 s, the throttle low for 0.5 s more, then the altitude loop.
assert abs(min(x[0] for x in steps if x[20] > 1000) - 1.5075) < 1e-9, min(x[0] for x in steps if x[20] > 1000)
# One FDM packet a step, each stamp once but for those sent again (out.resent; those sent before it
# listened are lost); the two answers to the prelude dropped as stale.
stamps = [x[0] for x in steps]
assert sorted(set(round(t - 0.005, 9) for t in stamps)) == [round(float(r["t"]), 9) for r in rows], "FDM stamps differ"
assert 0 <= len(stamps) - len(rows) <= int(rows[-1]["out.resent"]), (len(stamps), len(rows), rows[-1]["out.resent"])
assert int(rows[-1]["out.stale"]) >= 2
print(f"bf hover: z(12 s) = {z:.4f} m, mean rotor speed {mean_w:.1f} rad/s (closed form {hover:.1f}), "
      f"resent {rows[-1]['out.resent']}, stale {rows[-1]['out.stale']}")
PY
    ;;
  bf_deterministic)
    scenario a
    scenario b
    run a 0
    run b 0
    cmp "$tmp/a/trajectory.csv" "$tmp/b/trajectory.csv" || fail "two runs differ"
    echo "bf deterministic: trajectory.csv identical over two runs ($(wc -l < "$tmp/a/trajectory.csv") lines)"
    ;;
  bf_paced)
    # Paced at real time (realtime_factor 1, 3 s) with every 50th FDM packet answered 6 ms late (the step is
    # 2.5 ms): the packets still leave one a step (none sent twice), and a step whose answer missed the next
    # step's send time flies the motors it flew before (out.late counts it; the late answer is flown by the
    # next step).
    scenario paced --fake-late-every 50 --fake-record "$tmp/paced.rec"
    sed -i -e 's/realtime_factor: 0 .*/realtime_factor: 1/' -e 's/duration_s: 12/duration_s: 3/' "$tmp/paced.yaml"
    run paced 0
    "$py" - "$tmp/paced/trajectory.csv" "$tmp/paced.rec" <<'PY' || fail "paced"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
rec = [list(map(float, line.split())) for line in open(sys.argv[2])]
last = rows[-1]
assert int(last["out.resent"]) == 0, last["out.resent"]
# The prelude's two packets, then one per step, each stamp once.
assert len(rec) == len(rows) + 2, (len(rec), len(rows))
assert [round(x[0] - 0.005, 9) for x in rec[2:]] == [round(float(r["t"]), 9) for r in rows]
delayed = len(rec) // 50
late = int(last["out.late"])
assert late >= delayed, (late, delayed)
m = [[float(r[f"out.m{k}"]) for k in range(1, 5)] for r in rows]
held = 0
for k in range(1, len(rows)):
    if int(rows[k]["out.late"]) > int(rows[k - 1]["out.late"]) and rows[k]["out.stale"] == rows[k - 1]["out.stale"]:
        assert m[k] == m[k - 1], (rows[k]["t"], m[k], m[k - 1])
        held += 1
assert held >= 1, held
print(f"bf paced: {len(rows)} steps, {delayed} answers delayed, {late} steps flew held motors "
      f"({held} checked equal to the step before), stale {last['out.stale']}")
PY
    ;;
  bf_port_taken)
    # Another program holds UDP 9002 (Betaflight's motor port): the run is refused at once, naming the
    # port and why, and no firmware starts.
    "$py" -c "import socket,time; s=socket.socket(socket.AF_INET,socket.SOCK_DGRAM); s.bind(('127.0.0.1',9002)); open('$tmp/held','w').close(); time.sleep(60)" &
    pids+=($!)
    for _ in $(seq 100); do [ -f "$tmp/held" ] && break; sleep 0.05; done
    scenario taken --fake-pid-file "$tmp/taken.pid"
    run taken 5
    grep -q "UDP port 9002 on 127.0.0.1 is in use.*one Betaflight runs per network namespace" "$tmp/taken.log" ||
      fail "message: $(cat "$tmp/taken.log")"
    [ ! -f "$tmp/taken.pid" ] || fail "a firmware started"
    grep -o "UDP port 9002 .*namespace" "$tmp/taken.log" | head -1
    ;;
  bf_hang)
    # Silent from FDM packet 800 (step 797 after the two of the prelude): the run ends about timeout_s (2 s) later, the firmware killed.
    scenario hang --fake-hang-at 800 --fake-pid-file "$tmp/hang.pid"
    start=$SECONDS
    run hang 5
    took=$((SECONDS - start))
    [ "$took" -le 20 ] || fail "took $took s"
    grep -q "step 79[0-9] (t = 1.99[0-9]* s): no motor packet on UDP 9002 for 2 s (it went silent)" "$tmp/hang.log" ||
      fail "message: $(cat "$tmp/hang.log")"
    gone "$tmp/hang.pid"
    echo "bf hang: ended after $took s, firmware killed"
    ;;
  bf_spec)
    # Betaflight flies QUADX only; its section refuses ArduPilot's and PX4's keys; a missing binary
    # names its environment variable.
    sed -e "s|binary: fake_betaflight.*|binary: $fake_bf|" -e "s|layout: x|layout: plus|" \
      "$here/fake_betaflight_hover.yaml" > "$tmp/plus.yaml"
    run plus 2
    grep -q "QUADX mixer only" "$tmp/plus.log" || fail "plus: $(cat "$tmp/plus.log")"
    printf 'vehicle: {layout: x}\ncontroller: {sitl: {firmware: betaflight, binary: %s, mission: []}}\n' "$fake_bf" \
      > "$tmp/mission.yaml"
    run mission 2
    grep -q "controller.sitl.mission: is not Betaflight's" "$tmp/mission.log" || fail "mission: $(cat "$tmp/mission.log")"
    printf 'controller: {sitl: {firmware: ardupilot, binary: %s, arm_at_s: 1}}\n' "$fake_bf" > "$tmp/arm.yaml"
    run arm 2
    grep -q "controller.sitl.arm_at_s: is Betaflight's" "$tmp/arm.log" || fail "arm_at_s: $(cat "$tmp/arm.log")"
    printf 'vehicle: {layout: x}\ncontroller: {sitl: {firmware: betaflight}}\n' > "$tmp/nobin.yaml"
    rc=0; env -u QUADCOSIM_BETAFLIGHT_SITL "$bin" run "$tmp/nobin.yaml" --out "$tmp/x" > "$tmp/nobin.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && grep -q "controller.sitl.binary: missing.*QUADCOSIM_BETAFLIGHT_SITL" "$tmp/nobin.log" ||
      fail "missing binary: exit $rc $(cat "$tmp/nobin.log")"
    cat "$tmp/plus.log" "$tmp/mission.log" "$tmp/arm.log" "$tmp/nobin.log" | grep -i "sitl" | cut -c1-160
    ;;
  real_betaflight)
    # Betaflight's SITL build (QUADCOSIM_BETAFLIGHT_SITL) flies scenarios/sitl/betaflight_angle_hover.yaml
    # twice: armed from 2 s, 2 m held and nearly level; the roll stick step (9-11 s) rolls it right and
    # the pitch step (12-14 s) pitches its nose down (the frames, end to end); how far the two runs
    # differ is printed (its clock is wall time scaled, so they are not bit-identical: docs/sitl.md).
    if [ -z "${QUADCOSIM_BETAFLIGHT_SITL:-}" ] || [ ! -x "$QUADCOSIM_BETAFLIGHT_SITL" ]; then
      echo "SKIPPED: QUADCOSIM_BETAFLIGHT_SITL does not name Betaflight's SITL executable (obj/main/betaflight_SITL.elf of make TARGET=SITL, docs/sitl.md)"
      exit 77
    fi
    for n in r1 r2; do
      start=$SECONDS
      rc=0; "$bin" run "$src/scenarios/sitl/betaflight_angle_hover.yaml" --out "$tmp/$n" --judge none \
        > "$tmp/$n.log" 2>&1 || rc=$?
      [ "$rc" -eq 0 ] || fail "$n exited $rc: $(tail -5 "$tmp/$n.log")"
      echo "$n: $((SECONDS - start)) s wall"
    done
    "$py" - "$tmp/r1/trajectory.csv" "$tmp/r2/trajectory.csv" <<'PY' || fail "hover"
import csv, math, sys
runs = [list(csv.DictReader(open(p))) for p in sys.argv[1:3]]
def mean(rows, key, t0, t1):
    v = [float(r[key]) for r in rows if t0 <= float(r["t"]) < t1]
    return sum(v) / len(v)
for rows in runs:
    spun = [float(r["t"]) for r in rows if float(r["w1"]) > 0]
    assert spun and spun[0] >= 2.0 - 1e-9, spun[:1]
    hold = [float(r["z"]) for r in rows if 8 <= float(r["t"])]
    assert min(hold) > 1.7 and max(hold) < 2.3, (min(hold), max(hold))
    tilt = max(math.hypot(float(r["roll"]), float(r["pitch"])) for r in rows if float(r["t"]) >= 2.0)
    assert tilt < math.radians(10), math.degrees(tilt)
    # The steps: the commanded axis moves the commanded way by more than 0.01 rad (Betaflight's angle
    # mode reaches a fraction of the 0.1 rad asked: docs/sitl.md), the other stays within 0.01 rad.
    roll_step = mean(rows, "roll", 10, 11) - mean(rows, "roll", 8, 9)
    pitch_across = mean(rows, "pitch", 10, 11) - mean(rows, "pitch", 8, 9)
    pitch_step = mean(rows, "pitch", 13, 14) - mean(rows, "pitch", 11.5, 12)
    roll_across = mean(rows, "roll", 13, 14) - mean(rows, "roll", 11.5, 12)
    assert roll_step > 0.01 and abs(pitch_across) < 0.01, (roll_step, pitch_across)
    assert pitch_step > 0.01 and abs(roll_across) < 0.01, (pitch_step, roll_across)
a, b = runs
dz = max(abs(float(x["z"]) - float(y["z"])) for x, y in zip(a, b))
dtilt = max(abs(float(x["roll"]) - float(y["roll"])) + abs(float(x["pitch"]) - float(y["pitch"])) for x, y in zip(a, b))
print(f"real betaflight: motors from {spun[0]:.3f} s, z in [{min(hold):.3f}, {max(hold):.3f}] m after 8 s, "
      f"tilt <= {math.degrees(tilt):.2f} deg, roll step {roll_step:.4f} rad, pitch step {pitch_step:.4f} rad; two runs differ by up to {dz:.4f} m in z, "
      f"{math.degrees(dtilt):.3f} deg in roll + pitch; resent {a[-1]['out.resent']}/{b[-1]['out.resent']}, "
      f"stale {a[-1]['out.stale']}/{b[-1]['out.stale']}")
PY
    ;;
  *) echo "unknown case $case_name"; exit 2 ;;
esac
