#!/usr/bin/env bash
# Firmware in the loop with the test firmware (tests/sitl/fake_firmware.cpp): the whole JSON lockstep
# loop through `quadcosim run`, checked against closed forms and by its counts; and its failures
# (a wrong packet, a firmware that exits or hangs, a bad section), each a clear message and exit 5 or 2,
# never a hang, with the firmware process gone afterwards.
# Usage: sitl_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID FAKE_FIRMWARE
bin="$1"; src="$2"; fake="$5"
fake_px4="$(dirname "$fake")/fake_px4"  # built beside it (tests/sitl/fake_px4.cpp)
# shellcheck source=../lib/process_case.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
here="$src/tests/sitl"
py=/usr/bin/python3
# Before process_case.sh's cleanup: the firmware processes by their pid files, and the folders a failed
# run keeps (its message names it, with the log), those made here.
sitl_cleanup() {
  local f d
  set +e
  for f in "$tmp"/*.pid; do [ -f "$f" ] && { kill -KILL "$(cat "$f")" 2>/dev/null || true; }; done
  for d in $(grep -ho "/[^ ]*/quadcosim-sitl-[A-Za-z0-9]*" "$tmp"/*.log 2>/dev/null | sort -u); do rm -rf "$d"; done
}
trap 'sitl_cleanup; cleanup' EXIT
# scenario BASE NAME [ARG...]: BASE's scenario flying the built test firmware with ARGs, as $tmp/NAME.yaml.
scenario() {
  local base="$1" name="$2"; shift 2
  local args=""
  for a in "$@"; do args="$args\"$a\", "; done
  sed -e "s|binary: fake_firmware.*|binary: $fake|" -e "s|params: |params: $here/|" \
      -e "s|    timeout_s: 2|    timeout_s: 2\n    args: [${args%, }]|" "$here/$base.yaml" > "$tmp/$name.yaml"
}
# run NAME EXPECTED_RC: runs $tmp/NAME.yaml into $tmp/NAME/, output in $tmp/NAME.log.
run() {
  local name="$1" want="$2" rc=0
  "$bin" run "$tmp/$name.yaml" --out "$tmp/$name" --judge none > "$tmp/$name.log" 2>&1 || rc=$?
  [ "$rc" -eq "$want" ] || fail "$name exited $rc, expected $want"
}
# px4_scenario BASE NAME [ARG...]: BASE's scenario flying the built test PX4 with ARGs, as $tmp/NAME.yaml
# (its etc folder: one with an init.d-posix folder, as PX4's ROMFS has).
px4_scenario() {
  local base="$1" name="$2"; shift 2
  local args=""
  for a in "$@"; do args="$args\"$a\", "; done
  mkdir -p "$tmp/etc/init.d-posix"
  sed -e "s|binary: fake_px4.*|binary: $fake_px4|" -e "s|etc_dir: ETC.*|etc_dir: $tmp/etc|" -e "s|params: |params: $here/|" \
      -e "s|    timeout_s: 2|    timeout_s: 2\n    args: [${args%, }]|" "$here/$base.yaml" > "$tmp/$name.yaml"
}
# quiet_sensors FILE GNSS_EXTRA: appends PX4's home site and the sensors PX4 needs, nearly noiseless
# (PX4 refuses constant readings), the GNSS at 10 Hz with GNSS_EXTRA (", key: value, ...") added.
quiet_sensors() {
  cat >> "$1" <<YAML
environment:
  site: {latitude_deg: 47.397742, longitude_deg: 8.545594, altitude_m: 488}
sensors:
  imu: {gyro_noise_density_rad_s_sqrt_hz: 1.0e-7, accel_noise_density_m_s2_sqrt_hz: 1.0e-7}
  magnetometer: {rate_hz: 50, field_uT: 48.24, inclination_deg: 63.16, declination_deg: 3.41, noise_sigma_uT: 1.0e-6}
  barometer: {rate_hz: 50, noise_sigma_Pa: 1.0e-6}
  gnss: {rate_hz: 10, horizontal_sigma_m: 1.0e-6, vertical_sigma_m: 1.0e-6, velocity_sigma_m_s: 1.0e-6$2}
YAML
}
gone() {  # the firmware whose pid file is $1 no longer runs
  local pid; pid="$(cat "$1")"
  ! kill -0 "$pid" 2>/dev/null || fail "firmware $pid still runs after the run"
}

case "$case_name" in
  open_loop)
    # 1400 us on every motor: 4800 rad/s, z(t) = 10 + a t^2 / 2 with a = 4 k_t 4800^2 / m - g, from the
    # first tick (the firmware's first frame already commands 1400 us). One frame per 400 Hz step.
    scenario fake_open_loop ol --fake-pid-file "$tmp/ol.pid"
    run ol 0
    gone "$tmp/ol.pid"
    "$py" - "$tmp/ol/trajectory.csv" <<'PY' || fail "open-loop height"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
kt, m, g, w = 2.06e-7, 1.96, 9.81, 4800.0
a = 4 * kt * w * w / m - g  # -0.12378 m/s^2
assert len(rows) == 801, len(rows)
worst = max(abs(float(r["z"]) - (10 + 0.5 * a * float(r["t"]) ** 2)) for r in rows)
assert worst < 1e-9, f"height differs from the closed form by {worst} m"
for k, r in enumerate(rows):
    assert float(r["out.frame"]) == k, (k, r["out.frame"])
    assert all(float(r[f"w{i}"]) == w for i in range(1, 5)) or k == 0, (k, [r[f"w{i}"] for i in range(1, 5)])
last = rows[-1]
assert float(last["out.repeated"]) == 0 and float(last["out.skipped"]) == 0
print(f"open loop: z(2 s) = {float(last['z']):.9f} m, closed form {10 + 2 * a:.9f} m, worst {worst:.1e} m, 801 frames")
PY
    ;;
  hover)
    # From the ground to 2 m: held within 5 cm at 12 s, level, the rotors at the closed-form hover
    # speed sqrt(m g / 4 k_t) = 4830.6 rad/s within 1 % (integer PWM widths step it by 12 rad/s).
    scenario fake_hover hv --fake-pid-file "$tmp/hv.pid"
    run hv 0
    gone "$tmp/hv.pid"
    "$py" - "$tmp/hv/trajectory.csv" <<'PY' || fail "hover"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
last = rows[-1]
z = float(last["z"])
assert abs(z - 2.0) < 0.05, f"z(12 s) = {z}"
tail = [r for r in rows if float(r["t"]) >= 10.0]
mean_w = sum(sum(float(r[f"w{i}"]) for i in range(1, 5)) / 4 for r in tail) / len(tail)
hover = math.sqrt(1.96 * 9.81 / (4 * 2.06e-7))
assert abs(mean_w / hover - 1) < 0.01, (mean_w, hover)
assert max(abs(float(r["roll"])) + abs(float(r["pitch"])) for r in rows) < 1e-9
assert float(last["out.frame"]) == len(rows) - 1 and float(last["out.repeated"]) == 0
print(f"hover: z(12 s) = {z:.4f} m, mean rotor speed over the last 2 s {mean_w:.1f} rad/s (closed form {hover:.1f})")
PY
    ;;
  swarm)
    # A swarm of four vehicles, each flown by a test firmware process of its own on its own ports
    # (2x2 grid, 3 m apart): vehicle 0 gives the single vehicle's trajectory.csv bytes, vehicle 3 the
    # same numbers 3 m over in x and y; every firmware gone afterwards.
    scenario fake_hover one --fake-pid-file "$tmp/one.pid"
    scenario fake_hover sw --fake-pid-file "$tmp/sw.pid"
    printf 'swarm:\n  vehicles: 4\n  spacing_m: 3.0\n  threads: 2\n  record_vehicles: [0, 3]\n' >> "$tmp/sw.yaml"
    run one 0
    run sw 0
    ! pgrep -f -- "--fake-pid-file $tmp/sw.pid" > /dev/null || fail "a swarm firmware still runs after the run"
    cmp "$tmp/one/trajectory.csv" "$tmp/sw/uav0000/trajectory.csv" || fail "swarm vehicle 0 differs from the single run"
    "$py" - "$tmp/one/trajectory.csv" "$tmp/sw/uav0003/trajectory.csv" "$tmp/sw/vehicles.csv" <<'PY' || fail "swarm"
import csv, sys
one, v3 = (list(csv.DictReader(open(f))) for f in sys.argv[1:3])
assert len(one) == len(v3) == 4801, (len(one), len(v3))
for a, b in zip(one, v3):
    for k in a:
        if k in ("x", "y", "x_des", "y_des"):
            assert abs(float(b[k]) - float(a[k]) - 3.0) < 1e-12, (a["t"], k, a[k], b[k])
        else:
            assert a[k] == b[k], (a["t"], k, a[k], b[k])
vehicles = list(csv.DictReader(open(sys.argv[3])))
assert len(vehicles) == 4 and all(abs(float(v["z_m"]) - 2.0) < 0.05 for v in vehicles), vehicles
print(f"swarm: 4 firmware processes, z(12 s) = {[round(float(v['z_m']), 4) for v in vehicles]} m; "
      "vehicle 0 = the single run's bytes, vehicle 3 the same 3 m over")
PY
    ;;
  repeated_frames)
    # Frames sent twice (the first three times) are dropped and counted, never answered or flown twice:
    # the trajectory is the open-loop one, column for column, with 2 + 114 (frames 7, 14, ..., 798)
    # repeats counted.
    scenario fake_open_loop ol
    scenario fake_open_loop rep --fake-repeat-every 7 --fake-first-copies 3
    run ol 0
    run rep 0
    "$py" - "$tmp/ol/trajectory.csv" "$tmp/rep/trajectory.csv" <<'PY' || fail "repeated frames"
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
assert len(a) == len(b)
for ra, rb in zip(a, b):
    for k in ra:
        if k != "out.repeated":
            assert ra[k] == rb[k], (ra["t"], k, ra[k], rb[k])
assert float(b[-1]["out.repeated"]) == 116, b[-1]["out.repeated"]
assert float(b[-1]["out.skipped"]) == 0
print("repeated frames: 116 dropped and counted, trajectory identical to the run without")
PY
    ;;
  deterministic)
    scenario fake_hover a
    scenario fake_hover b
    run a 0
    run b 0
    cmp "$tmp/a/trajectory.csv" "$tmp/b/trajectory.csv" || fail "two runs differ"
    echo "deterministic: trajectory.csv identical over two runs ($(wc -l < "$tmp/a/trajectory.csv") lines)"
    ;;
  bad_magic)
    scenario fake_open_loop bm --fake-bad-magic-at 100 --fake-pid-file "$tmp/bm.pid"
    run bm 5
    grep -q "controller sitl (ardupilot .*fake_firmware).*step 100 .*magic" "$tmp/bm.log" || fail "message: $(cat "$tmp/bm.log")"
    gone "$tmp/bm.pid"
    [ "$(($(wc -l < "$tmp/bm/trajectory.csv") - 1))" -eq 100 ] || fail "expected the 100 ticks before the bad packet"
    grep "magic" "$tmp/bm.log" | head -1
    ;;
  firmware_dies)
    scenario fake_open_loop die --fake-die-at 50
    run die 5
    grep -q "step 50 .*the firmware exited with status 3" "$tmp/die.log" || fail "message: $(cat "$tmp/die.log")"
    grep -q "dying at frame 50" "$tmp/die.log" || fail "the firmware's log is not quoted"
    grep "exited with status 3" "$tmp/die.log" | head -1 | cut -c1-200
    ;;
  firmware_hangs)
    # Silent from frame 200 (t = 0.5 s): the run ends about timeout_s (2 s) later, the firmware killed.
    scenario fake_open_loop hang --fake-hang-at 200 --fake-pid-file "$tmp/hang.pid"
    start=$SECONDS
    run hang 5
    took=$((SECONDS - start))
    [ "$took" -le 15 ] || fail "took $took s"
    grep -q "no servo packet for 2 s (frame 200: it went silent)" "$tmp/hang.log" || fail "message: $(cat "$tmp/hang.log")"
    gone "$tmp/hang.pid"
    echo "firmware hangs: ended after $took s, firmware killed"
    ;;
  dds)
    # The firmware as the controller of `run --transport dds` (the controller process starts it): the
    # same trajectory.csv bytes as in-process.
    scenario fake_hover inproc
    cp "$tmp/inproc.yaml" "$tmp/overdds.yaml"
    run inproc 0
    rc=0; "$bin" run "$tmp/overdds.yaml" --out "$tmp/overdds" --transport dds --judge none > "$tmp/overdds.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail "over DDS: exit $rc"
    cmp "$tmp/inproc/trajectory.csv" "$tmp/overdds/trajectory.csv" || fail "over DDS the trajectory differs"
    echo "dds: the test firmware over DDS, trajectory.csv identical to in-process"
    ;;
  imu_noise)
    # The IMU the firmware is sent is the one realism makes: gyro white noise of density
    # 0.001 rad/s/sqrt(Hz) at 400 Hz is sigma = 0.001 sqrt(400) = 0.02 rad/s per axis on a vehicle
    # whose true rates stay 0 (open loop, level); the accelerometer (no noise) reads the specific
    # force 4 k_t 4800^2 / m = 9.686204 m/s^2 along -z FRD.
    scenario fake_open_loop noisy --fake-record "$tmp/received.txt"
    printf 'sensors:\n  imu:\n    rate_hz: 400\n    gyro_noise_density_rad_s_sqrt_hz: 0.001\n' >> "$tmp/noisy.yaml"
    run noisy 0
    "$py" - "$tmp/received.txt" "$tmp/noisy/trajectory.csv" <<'PY' || fail "imu noise"
import csv, math, sys
rec = [list(map(float, l.split())) for l in open(sys.argv[1])]
truth = list(csv.DictReader(open(sys.argv[2])))
assert max(abs(float(r[k])) for r in truth for k in ("p", "q", "r")) == 0.0
assert len(rec) >= 800, len(rec)
for axis in (1, 2, 3):
    v = [r[axis] for r in rec]
    m = sum(v) / len(v)
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))
    assert 0.018 < sd < 0.022 and abs(m) < 0.003, (axis, m, sd)
f = 4 * 2.06e-7 * 4800.0 ** 2 / 1.96
assert all(abs(r[6] + f) < 1e-9 and r[4] == 0 and r[5] == 0 for r in rec), rec[:2]
print(f"imu noise: the firmware received gyro sigma {sd:.4f} rad/s (expected 0.02), accel z {rec[-1][6]:.6f} (expected {-f:.6f})")
PY
    ;;
  faults)
    # A rotor fault reaches the ArduPilot-side test firmware in the IMU it is sent, as numbers it did
    # not make: rotor 1 (the nose of the '+' layout, clockwise) at 75 % from 1 s under its open-loop
    # law (every motor at 1400 us: 4800 rad/s). The accelerometer reads -4 k_t w^2 / m on FRD z
    # before and -3.75 k_t w^2 / m from the fault's tick on; the gyro 0 before and, from rest after it,
    # tau / I (t - 1 s): about FRD y -l dF / I_yy (nose down), about z (k_m / k_t) dF / I_zz (less of a
    # clockwise rotor's reaction), none about x (the Euler coupling adds 0.43 (t - 1)^3 rad/s there).
    scenario fake_open_loop fa --fake-record "$tmp/received.txt"
    printf 'faults:\n  - {at_s: 1, rotor: 1, efficiency: 0.75}\n' >> "$tmp/fa.yaml"
    run fa 0
    "$py" - "$tmp/received.txt" <<'PY' || fail "a rotor fault reaching the test firmware"
import sys
rec = [list(map(float, l.split())) for l in open(sys.argv[1])]
kt, m, l, km_over_kt = 2.06e-7, 1.96, 0.59, 0.5e-3  # Table 1
I = (0.0149, 0.0153, 0.0532)
F = kt * 4800.0 ** 2
dF = 0.25 * F
tau_frd = (0.0, -l * dF, km_over_kt * dF)  # FLU (0, l dF, -k dF) -> FRD (x, -y, -z)
assert len(rec) >= 800, len(rec)
seen = 0
for r in rec:
    t, gyro, az = r[0], r[1:4], r[6]
    if t < 1 - 1e-9:
        assert abs(az + 4 * F / m) < 1e-9 and max(abs(g) for g in gyro) == 0, r
    else:
        assert abs(az + 3.75 * F / m) < 1e-9, (t, az, -3.75 * F / m)
        if t < 1.1:
            for i in range(3):
                want = tau_frd[i] / I[i] * (t - 1)
                assert abs(gyro[i] - want) < 2e-3 * abs(want) + 5e-4, (t, i, gyro[i], want)
            seen += 1
assert seen >= 40, seen
print(f"faults: the firmware's accel z {-4 * F / m:.6f} -> {-3.75 * F / m:.6f} m/s^2 at 1 s, gyro y "
      f"{tau_frd[1] / I[1]:.3f} rad/s^2 and z {tau_frd[2] / I[2]:.5f} rad/s^2 times (t - 1 s) ({seen} frames)")
PY
    ;;
  firmware_panics)
    # A PANIC line in the firmware's log while it starts ends the run at once (start_timeout_s is 30 s),
    # quoting it; and a scenario given by a relative path passes absolute parameter paths.
    scenario fake_open_loop panic --fake-panic
    start=$SECONDS
    run panic 5
    [ $((SECONDS - start)) -le 10 ] || fail "took $((SECONDS - start)) s"
    grep -q "step 0: the firmware panicked while starting: PANIC: Failed to load defaults" "$tmp/panic.log" ||
      fail "message: $(cat "$tmp/panic.log")"
    grep -q "fake_open_loop.parm" "$tmp/panic.log" || fail "the parameter file is not named"
    (cd "$src" && "$bin" run tests/sitl/fake_open_loop.yaml --controller "sitl:ardupilot:$fake" --out "$tmp/rel" \
      --judge none > "$tmp/rel.log" 2>&1) || fail "relative scenario path: $(tail -3 "$tmp/rel.log")"
    grep -q "PANIC" "$tmp/panic.log" | head -1
    ;;
  interrupted)
    # Ctrl-C (SIGINT to quadcosim) while the firmware hangs: exit 130 within 2 s, not after timeout_s
    # (set to 30 s here), the firmware gone.
    scenario fake_open_loop intr --fake-hang-at 100 --fake-pid-file "$tmp/intr.pid"
    sed -i "s|timeout_s: 2|timeout_s: 30\n    work_dir: $tmp/fw|" "$tmp/intr.yaml"
    "$bin" run "$tmp/intr.yaml" --out "$tmp/intr" --judge none --no-plots > "$tmp/intr.log" 2>&1 &
    q=$!
    echo "$q" > "$tmp/q.pid"
    for _ in $(seq 100); do grep -q "hanging at frame 100" "$tmp/fw/firmware.log" 2>/dev/null && break; sleep 0.1; done
    sleep 0.3
    start=$("$py" -c 'import time; print(time.monotonic())')
    kill -INT "$q"
    rc=0; wait "$q" || rc=$?
    took=$("$py" -c "import time; print(f'{time.monotonic() - $start:.2f}')")
    [ "$rc" -eq 130 ] || fail "exit $rc $(cat "$tmp/intr.log")"
    "$py" -c "import sys; sys.exit(0 if $took < 2.0 else 1)" || fail "took $took s"
    gone "$tmp/intr.pid"
    echo "interrupted: exit 130 after $took s, firmware gone"
    ;;
  bad_spec)
    # A missing binary, one that is not executable, a params file that does not exist, an unknown key.
    cat > "$tmp/nobin.yaml" <<YAML
controller: {sitl: {firmware: ardupilot}}
YAML
    rc=0; env -u QUADCOSIM_ARDUPILOT_SITL "$bin" run "$tmp/nobin.yaml" --out "$tmp/x" > "$tmp/nobin.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] || fail "missing binary: exit $rc"
    grep -q "controller.sitl.binary: missing.*QUADCOSIM_ARDUPILOT_SITL" "$tmp/nobin.log" || fail "$(cat "$tmp/nobin.log")"
    cat > "$tmp/notexec.yaml" <<YAML
controller: {sitl: {binary: $here/fake_hover.parm}}
YAML
    rc=0; "$bin" run "$tmp/notexec.yaml" --out "$tmp/x" > "$tmp/notexec.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && grep -q "controller.sitl.binary: .*is not an executable file" "$tmp/notexec.log" ||
      fail "not executable: exit $rc $(cat "$tmp/notexec.log")"
    cat > "$tmp/noparm.yaml" <<YAML
controller: {sitl: {binary: $fake, params: [nothere.parm]}}
YAML
    rc=0; "$bin" run "$tmp/noparm.yaml" --out "$tmp/x" > "$tmp/noparm.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && grep -q "controller.sitl.params: .*nothere.parm" "$tmp/noparm.log" ||
      fail "missing params: exit $rc $(cat "$tmp/noparm.log")"
    cat > "$tmp/unknown.yaml" <<YAML
controller: {sitl: {binary: $fake, timeout: 3}}
YAML
    rc=0; "$bin" run "$tmp/unknown.yaml" --out "$tmp/x" > "$tmp/unknown.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && grep -q "controller.sitl.timeout" "$tmp/unknown.log" || fail "unknown key: exit $rc $(cat "$tmp/unknown.log")"
    cat "$tmp/nobin.log" "$tmp/notexec.log" "$tmp/noparm.log" "$tmp/unknown.log" | grep -i "error\|sitl" | head -4
    ;;
  mission)
    # A mission over MAVLink: the arm command is refused until the firmware is ready (2 s) and sent again
    # each second, so it is accepted at the 2.25 s decision; then take off to 3 m, a 5 m target at 8 s,
    # land at 14 s (disarmed on the ground). Twice: the same bytes.
    scenario fake_mission m1
    scenario fake_mission m2
    run m1 0
    run m2 0
    cmp "$tmp/m1/trajectory.csv" "$tmp/m2/trajectory.csv" || fail "two mission runs differ"
    "$py" - "$tmp/m1/trajectory.csv" <<'PY' || fail "mission"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
at = lambda t: rows[round(t * 400)]
armed = [float(r["t"]) for r in rows if r["out.armed"] == "1"]
assert armed and 2.25 <= armed[0] <= 3.25, armed[:1]
assert all(float(r["z"]) == 0.0 for r in rows if float(r["t"]) < 2.25)
assert abs(float(at(7.5)["z"]) - 3) < 0.3, at(7.5)["z"]
assert abs(float(at(13.5)["z"]) - 5) < 0.3, at(13.5)["z"]
last = rows[-1]
assert float(last["z"]) == 0.0 and last["out.armed"] == "0" and last["out.mode"] == "9", last
assert float(last["out.mission"]) == 5
# out.armed and out.mode are the heartbeat as seen at the 0.25 s decisions: after the first one (the
# first heartbeat's frame) they change only at whole multiples of 0.25 s.
shown = [(float(r["t"]), r["out.armed"], r["out.mode"]) for r in rows]
changes = [t for (t, *a), (_, *b) in zip(shown[1:], shown) if a != b][1:]
assert changes and all(abs(t * 4 - round(t * 4)) < 1e-9 for t in changes), changes
print(f"mission: armed at {armed[0]:.4f} s, z(7.5 s) = {float(at(7.5)['z']):.3f} m, "
      f"z(13.5 s) = {float(at(13.5)['z']):.3f} m, landed and disarmed; two runs identical")
PY
    ;;
  controller_flag)
    # --controller sitl:ardupilot:BINARY flies a scenario written for another controller with the
    # firmware; the file's sitl section (params, timeouts) is kept when it has one. The open-loop
    # scenario flown by the paper controller first, then by the test firmware through the flag.
    sed -e "/^controller:/,/^analysis:/{/^analysis:/!d}" "$here/fake_open_loop.yaml" > "$tmp/paper.yaml"
    sed -i "s|^analysis:|controller:\n  sitl:\n    params: $here/fake_open_loop.parm\nanalysis:|" "$tmp/paper.yaml"
    rc=0; "$bin" run "$tmp/paper.yaml" --controller "sitl:ardupilot:$fake" --out "$tmp/flag" --judge none \
      > "$tmp/flag.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail "exit $rc"
    grep -q "type: sitl" "$tmp/flag/scenario.yaml" && grep -q "binary: $fake" "$tmp/flag/scenario.yaml" ||
      fail "scenario.yaml does not say what flew: $(cat "$tmp/flag/scenario.yaml")"
    [ "$(tail -1 "$tmp/flag/trajectory.csv" | cut -d, -f4)" = "9.75240816326531" ] || fail "not the open-loop flight"
    rc=0; "$bin" run "$tmp/paper.yaml" --controller "sitl:inav" --out "$tmp/x" > "$tmp/bf.log" 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && grep -q "expected sitl:ardupilot\[:BINARY\], sitl:px4\[:BINARY\] or sitl:betaflight" "$tmp/bf.log" ||
      fail "sitl:inav: exit $rc $(cat "$tmp/bf.log")"
    # A file whose gains sit directly under controller: (the paper controller's, the older form): they
    # move into its paper: section, checked and unused, and the firmware flies.
    sed -e "s/duration_s: .*/duration_s: 1/" "$src/tests/faults/hover_gusts.yaml" > "$tmp/flat.yaml"
    rc=0; "$bin" run "$tmp/flat.yaml" --controller "sitl:ardupilot:$fake" --out "$tmp/flat" --judge none --no-plots \
      > "$tmp/flat.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail "flat gains: exit $rc $(grep error "$tmp/flat.log")"
    grep -q "^  paper:" "$tmp/flat/scenario.yaml" || fail "the flat gains did not move to paper:"
    echo "controller flag: sitl:ardupilot:BINARY flew the open-loop file, z(2 s) as expected"
    ;;
  real_mission)
    # ArduCopter's SITL build (QUADCOSIM_ARDUPILOT_SITL) flies scenarios/sitl/takeoff_waypoint_land.yaml
    # twice: the same trajectory.csv bytes; it arms once its EKF is ready, holds 10 m, reaches the
    # waypoint (10, 5, 10), lands and disarms; one frame per tick, none repeated or skipped.
    if [ -z "${QUADCOSIM_ARDUPILOT_SITL:-}" ] || [ ! -x "$QUADCOSIM_ARDUPILOT_SITL" ]; then
      echo "SKIPPED: QUADCOSIM_ARDUPILOT_SITL does not name ArduCopter's SITL executable (docs/sitl.md)"
      exit 77
    fi
    for n in r1 r2; do
      rc=0; "$bin" run "$src/scenarios/sitl/takeoff_waypoint_land.yaml" --out "$tmp/$n" --judge none \
        > "$tmp/$n.log" 2>&1 || rc=$?
      [ "$rc" -eq 0 ] || fail "$n exited $rc"
    done
    cmp "$tmp/r1/trajectory.csv" "$tmp/r2/trajectory.csv" || fail "two runs of the same firmware differ"
    "$py" - "$tmp/r1/trajectory.csv" <<'PY' || fail "mission"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
rate = round(1 / (float(rows[1]["t"]) - float(rows[0]["t"])))  # the scenario's frame rate (400 Hz shipped: one frame per ArduCopter loop)
at = lambda t: rows[round(t * rate)]
armed = [float(r["t"]) for r in rows if r["out.armed"] == "1"]
assert armed, "never armed"
hold = [float(r["z"]) for r in rows if 52 <= float(r["t"]) <= 60]
assert min(hold) > 9.5 and max(hold) < 10.5, (min(hold), max(hold))
wp = [math.hypot(float(r["x"]) - 10, float(r["y"]) - 5) for r in rows if 70 <= float(r["t"]) <= 80]
assert max(wp) < 0.3, max(wp)
last = rows[-1]
assert float(last["z"]) < 0.05 and last["out.armed"] == "0", (last["z"], last["out.armed"])
assert float(last["out.frame"]) - float(rows[0]["out.frame"]) == len(rows) - 1
assert float(last["out.repeated"]) == 0 and float(last["out.skipped"]) == 0
print(f"real mission: armed at {armed[0]:.2f} s, 10 m held within [{min(hold):.3f}, {max(hold):.3f}] m, "
      f"waypoint within {max(wp):.3f} m, landed and disarmed at {armed[-1]:.2f} s; two runs identical")
PY
    ;;
  px4_open_loop)
    # The test PX4 holds every output at 0.4 (4800 rad/s) from 10 m: z(t) = 10 + a t^2 / 2 at every
    # tick, answered from the first HIL_SENSOR, one answer a step; the sensors the file lacks added.
    px4_scenario fake_px4_open_loop ol --fake-pid-file "$tmp/ol.pid"
    run ol 0
    gone "$tmp/ol.pid"
    grep -q "added with their defaults (docs/sitl.md): environment.site, sensors.imu, sensors.magnetometer, sensors.barometer, sensors.gnss" \
      "$tmp/ol.log" || fail "the added sensors are not noted: $(cat "$tmp/ol.log")"
    "$py" - "$tmp/ol/trajectory.csv" <<'PY' || fail "open-loop height"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
kt, m, g = 2.06e-7, 1.96, 9.81
w = 0.4000000059604645 * 12000  # the float 0.4 PX4's message carries, times omega_max
a = 4 * kt * w * w / m - g
assert len(rows) == 501, len(rows)
worst = max(abs(float(r["z"]) - (10 + 0.5 * a * float(r["t"]) ** 2)) for r in rows)
assert worst < 1e-9, f"height differs from the closed form by {worst} m"
for k, r in enumerate(rows[:-1]):
    assert float(r["out.frame"]) == k + 1, (k, r["out.frame"])
    assert all(float(r[f"w{i}"]) == w for i in range(1, 5)) or k == 0, (k, [r[f"w{i}"] for i in range(1, 5)])
    assert r["out.u1"] == "0.4000000059604645" and r["out.armed"] == "1", r
assert all(float(r["x"]) == 3 and float(r["y"]) == 4 for r in rows)
print(f"px4 open loop: z(2 s) = {float(rows[-1]['z']):.9f} m, closed form {10 + 2 * a:.9f} m, worst {worst:.1e} m")
PY
    ;;
  px4_sensors)
    # What reaches the test PX4, in PX4's units, against formulas written here: the open-loop flight
    # above at (3, 4) east/north of PX4's home with nearly noiseless sensors. HIL_SENSOR every step at
    # time (n + 1) 4 ms; the specific force -4 k_t w^2 / m on FRD z; the magnetometer's field in gauss
    # in the body FRD frame (nose east) at 50 Hz; the standard atmosphere's pressure in hPa at
    # 488 m + z at 50 Hz; HIL_GPS at 10 Hz with latitude and longitude in degE7 from the radii of
    # curvature of the WGS-84 ellipsoid, altitude in mm, vertical speed in cm/s.
    px4_scenario fake_px4_open_loop se --fake-record "$tmp/received.txt"
    quiet_sensors "$tmp/se.yaml" ""
    run se 0
    "$py" - "$tmp/received.txt" <<'PY' || fail "sensors"
import math, sys
S = [l.split() for l in open(sys.argv[1]) if l.startswith("S ")]
G = [l.split() for l in open(sys.argv[1]) if l.startswith("G ")]
kt, m, g0 = 2.06e-7, 1.96, 9.81
w = 0.4000000059604645 * 12000
acc = 4 * kt * w * w / m - g0
z = lambda t: 10 + 0.5 * acc * t * t
assert len(S) == 501, len(S)
F, I, D = 48.24, math.radians(63.16), math.radians(3.41)
north, east, down = F * math.cos(I) * math.cos(D), F * math.cos(I) * math.sin(D), F * math.sin(I)
mag_frd = (east / 100, -north / 100, down / 100)  # nose east: x = east, y (right) = south, z = down; 100 uT = 1 G
def isa_hpa(h):  # ISO 2533 troposphere, constants as published
    T0, L, g, M, R = 288.15, 0.0065, 9.80665, 0.0289644, 8.31432
    return 1013.25 * (1 - L * h / T0) ** (g * M / (R * L))
worst = {"acc": 0, "mag": 0, "p": 0}
for n, s in enumerate(S):
    t_us, fields = int(s[1]), int(s[14])
    assert t_us == (n + 1) * 4000, (n, t_us)
    assert fields & 0x3F == 0x3F, fields
    assert abs(float(s[4]) + 4 * kt * w * w / m) < 1e-4 or n == 0, s
    worst["acc"] = max(worst["acc"], abs(float(s[4]) + 4 * kt * w * w / m)) if n else 0
    has_mag, has_baro = fields & 0x1C0 == 0x1C0, fields & 0x1A00 == 0x1A00
    assert has_mag == (n % 5 == 0) and has_baro == (n % 5 == 0), (n, hex(fields))
    if has_mag:
        d = max(abs(float(s[8 + i]) - mag_frd[i]) for i in range(3))
        worst["mag"] = max(worst["mag"], d)
        assert d < 2e-7, (n, s[8:11], mag_frd)
    if has_baro:
        t = 0.004 * n
        p = isa_hpa(488 + z(t))
        worst["p"] = max(worst["p"], abs(float(s[11]) - p))
        assert abs(float(s[11]) - p) < 2e-4, (n, s[11], p)
        assert abs(float(s[12]) - (488 + z(t))) < 0.01 and abs(float(s[13]) - (15 - 0.0065 * (488 + z(t)))) < 1e-3, s
a, f = 6378137.0, 1 / 298.257223563
e2 = f * (2 - f)
lat0, lon0 = math.radians(47.397742), math.radians(8.545594)
assert len(G) == 21, len(G)  # 0, 0.1, ..., 2.0 s
for k, gps in enumerate(G):
    t = 0.1 * k
    h = 488 + z(t)
    Mr = a * (1 - e2) / (1 - e2 * math.sin(lat0) ** 2) ** 1.5  # meridian radius of curvature
    Nr = a / math.sqrt(1 - e2 * math.sin(lat0) ** 2)            # prime vertical
    lat = math.degrees(lat0 + 4 / (Mr + h)) * 1e7
    lon = math.degrees(lon0 + 3 / ((Nr + h) * math.cos(lat0))) * 1e7
    assert abs(int(gps[2]) - lat) <= 1 and abs(int(gps[3]) - lon) <= 1, (k, gps[2:4], lat, lon)
    assert abs(int(gps[4]) - h * 1000) <= 2, (k, gps[4], h)
    assert int(gps[1]) == 1767225600 * 10**6 + round(t * 1e6), gps[1]
    assert abs(int(gps[10]) - (-acc * t * 100)) <= 1, (k, gps[10], -acc * t * 100)  # vd [cm/s], down
    assert gps[5] == "1" and gps[6] == "1" and gps[12] == "3" and gps[13] == "10", gps
print(f"px4 sensors: 501 HIL_SENSOR, 21 HIL_GPS; worst accel {worst['acc']:.1e} m/s^2, field {worst['mag']:.1e} G, "
      f"pressure {worst['p']:.1e} hPa; lat/lon within 1e-7 deg, alt within 2 mm")
PY
    ;;
  px4_mission)
    # A mission over the GCS link: take off (param7 = 488 + 3 m above mean sea level), arm (refused
    # at 1.25 s, the test PX4 ready at 2 s, accepted at the 2.25 s decision), a reposition as COMMAND_INT to the degE7 of (2, 1)
    # east/north at 493 m, land; the test PX4 hovers at the closed-form speed sqrt(m g / 4 k_t) through
    # the MPC_THR_HOVER quadcosim passes it. Twice: the same bytes.
    px4_scenario fake_px4_mission m1 --fake-record "$tmp/m1.txt"
    px4_scenario fake_px4_mission m2
    run m1 0
    run m2 0
    cmp "$tmp/m1/trajectory.csv" "$tmp/m2/trajectory.csv" || fail "two mission runs differ"
    "$py" - "$tmp/m1/trajectory.csv" "$tmp/m1.txt" <<'PY' || fail "mission"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
C = [l.split() for l in open(sys.argv[2]) if l.startswith("C ")]
at = lambda t: rows[round(t * 250)]
assert all(r["out.frame"] == "0" for r in rows[:10]) and rows[10]["out.frame"] == "1", [r["out.frame"] for r in rows[:12]]
armed = [float(r["t"]) for r in rows if r["out.armed"] == "1"]
assert armed and 2.25 <= armed[0] < 2.26, armed[:1]  # refused at 1.25 s, accepted at 2.25 s
takeoff = [c for c in C if c[1] == "22"]
assert float(takeoff[0][4]) == 491.0, takeoff
rep = [c for c in C if c[1] == "192"]
assert len(rep) == 1, rep
a, f = 6378137.0, 1 / 298.257223563
e2 = f * (2 - f)
lat0, lon0, h = math.radians(47.397742), math.radians(8.545594), 493.0
Mr = a * (1 - e2) / (1 - e2 * math.sin(lat0) ** 2) ** 1.5
Nr = a / math.sqrt(1 - e2 * math.sin(lat0) ** 2)
lat = math.degrees(lat0 + 1 / (Mr + h)) * 1e7
lon = math.degrees(lon0 + 2 / ((Nr + h) * math.cos(lat0))) * 1e7
assert abs(int(rep[0][2]) - lat) <= 1 and abs(int(rep[0][3]) - lon) <= 1 and float(rep[0][4]) == 493.0, (rep, lat, lon)
assert abs(float(at(7.5)["z"]) - 3) < 0.1, at(7.5)["z"]
assert abs(float(at(13.5)["z"]) - 5) < 0.1, at(13.5)["z"]
hold = [r for r in rows if 12 <= float(r["t"]) < 14]
mean_w = sum(float(r["w1"]) for r in hold) / len(hold)
hover = math.sqrt(1.96 * 9.81 / (4 * 2.06e-7))
assert abs(mean_w / hover - 1) < 0.002, (mean_w, hover)
last = rows[-1]
assert float(last["z"]) == 0.0 and last["out.armed"] == "0", (last["z"], last["out.armed"])
assert last["out.mode"] == str(4 << 16 | 6 << 24) and last["out.mission"] == "4", (last["out.mode"], last["out.mission"])
print(f"px4 mission: armed at {armed[0]} s, takeoff to 491 m AMSL, reposition at degE7 ({rep[0][2]}, {rep[0][3]}), "
      f"z(7.5) = {float(at(7.5)['z']):.3f}, z(13.5) = {float(at(13.5)['z']):.3f} m, hover {mean_w:.1f} rad/s "
      f"(closed form {hover:.1f}), landed; two runs identical")
PY
    ;;
  px4_dds)
    # The test PX4's mission as the controller of `run --transport dds` (the controller process starts
    # the test PX4; its magnetometer, barometer and GNSS samples cross DDS): the in-process bytes.
    px4_scenario fake_px4_mission inproc
    cp "$tmp/inproc.yaml" "$tmp/overdds.yaml"
    run inproc 0
    rc=0; "$bin" run "$tmp/overdds.yaml" --out "$tmp/overdds" --transport dds --judge none > "$tmp/overdds.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail "over DDS: exit $rc $(tail -3 "$tmp/overdds.log")"
    cmp "$tmp/inproc/trajectory.csv" "$tmp/overdds/trajectory.csv" || fail "over DDS the trajectory differs"
    echo "px4 dds: the test PX4's mission over DDS, trajectory.csv identical to in-process"
    ;;
  px4_failures)
    # Each a message naming the firmware, the step and its time, exit 5, the test PX4 gone.
    px4_scenario fake_px4_open_loop die --fake-die-at 100 --fake-pid-file "$tmp/die.pid"
    run die 5
    grep -q "controller sitl (px4 .*fake_px4): step 99 (t = 0.3960 s): the firmware exited with status 3" "$tmp/die.log" ||
      fail "dies: $(cat "$tmp/die.log")"
    grep -q "fake px4: instance" "$tmp/die.log" || fail "the firmware's log is not quoted"
    gone "$tmp/die.pid"
    [ "$(($(wc -l < "$tmp/die/trajectory.csv") - 1))" -eq 99 ] || fail "expected the 99 ticks before"
    px4_scenario fake_px4_open_loop hang --fake-hang-at 200 --fake-pid-file "$tmp/hang.pid"
    start=$SECONDS
    run hang 5
    [ $((SECONDS - start)) -le 15 ] || fail "hang took $((SECONDS - start)) s"
    grep -q "step 199 (t = 0.7960 s): no HIL_ACTUATOR_CONTROLS for 2 s (it went silent)" "$tmp/hang.log" ||
      fail "hangs: $(cat "$tmp/hang.log")"
    gone "$tmp/hang.pid"
    px4_scenario fake_px4_open_loop crc --fake-bad-crc-at 50 --fake-pid-file "$tmp/crc.pid"
    run crc 5
    grep -q "step 49 (t = 0.1960 s): a frame with a wrong checksum on the simulator link" "$tmp/crc.log" ||
      fail "bad crc: $(cat "$tmp/crc.log")"
    gone "$tmp/crc.pid"
    px4_scenario fake_px4_open_loop nls --fake-no-lockstep
    run nls 5
    grep -q "step 0 (t = 0.0000 s): HIL_ACTUATOR_CONTROLS without the lockstep flag" "$tmp/nls.log" ||
      fail "no lockstep: $(cat "$tmp/nls.log")"
    grep -h "controller sitl (px4" "$tmp/die.log" "$tmp/hang.log" "$tmp/crc.log" "$tmp/nls.log" | cut -c1-160
    ;;
  px4_faults)
    # Faults and realism of the scenario reach the test PX4, in numbers it did not make: rotor 1 (the
    # nose of the '+' layout, clockwise) at 75 % efficiency from 1 s under the open-loop law (every output 0.4, 4800
    # rad/s) and a GNSS without a fix before 0.5 s. The accelerometer reads -4 k_t w^2 / m on FRD z
    # before the fault and -(3 + 0.75) k_t w^2 / m from the fault's tick on (the body-frame specific
    # force does not depend on the tilt; no drag); the gyro reads 0 before it and, after it, the rates
    # the lost quarter of rotor 1's thrust and torque drive from rest: tau / I (t - 1 s), none about FRD x,
    # about y l dF / I_yy (nose down: negative) and about z (k_m / k_t) dF / I_zz (less of a clockwise
    # rotor's reaction: positive); HIL_GPS says no fix (fix_type 1, no satellites) at 0, 0.1, ..., 0.4 s, a 3D fix
    # with 10 satellites from 0.5 s on, every 0.1 s, but none again over the outage [1.2 s, 1.5 s): 1.2, 1.3, 1.4 s.
    px4_scenario fake_px4_open_loop fa --fake-record "$tmp/faults.txt"
    quiet_sensors "$tmp/fa.yaml" ", fix_after_s: 0.5, outage_from_s: 1.2, outage_to_s: 1.5"
    cat >> "$tmp/fa.yaml" <<'YAML'
faults:
  - {at_s: 1, rotor: 1, efficiency: 0.75}
YAML
    run fa 0
    "$py" - "$tmp/faults.txt" <<'PY' || fail "faults reaching the test PX4"
import math, sys
S = [l.split() for l in open(sys.argv[1]) if l.startswith("S ")]
G = [l.split() for l in open(sys.argv[1]) if l.startswith("G ")]
kt, m, l, km_over_kt = 2.06e-7, 1.96, 0.59, 0.5e-3  # Table 1: k_t, mass, arm, k_m / k_t
Ixx, Iyy, Izz = 0.0149, 0.0153, 0.0532
w = 0.4000000059604645 * 12000
F = kt * w * w                       # one rotor's thrust at 4800 rad/s
dF = 0.25 * F                        # what rotor 1 lost
tau_frd = (0.0, -l * dF, km_over_kt * dF)  # '+': rotor 1 at (l, 0) in FLU; FLU (0, l dF, -k dF) -> FRD (x, -y, -z)
I = (Ixx, Iyy, Izz)
assert len(S) == 501, len(S)
n_fault = None
worst = [0.0, 0.0]
for n, s in enumerate(S[1:], 1):
    t = 0.004 * n                    # the state's time (HIL_SENSOR n is stamped (n + 1) 4 ms)
    az, gyro = float(s[4]), [float(v) for v in s[5:8]]
    if t < 1 - 1e-9:
        assert abs(az + 4 * F / m) < 1e-4, (n, az, -4 * F / m)
        assert max(abs(g) for g in gyro) < 1e-4, (n, gyro)
    else:
        assert abs(az + 3.75 * F / m) < 1e-4, (n, az, -3.75 * F / m)
        if t < 1.1:                  # from rest: rate = tau / I (t - 1); the Euler coupling (I_yy - I_zz) q r / I_xx
                                     # adds 0.43 (t - 1)^3 rad/s about x, under 5e-4 by 1.1 s
            for i in range(3):
                want = tau_frd[i] / I[i] * (t - 1)
                worst[0] = max(worst[0], abs(gyro[i] - want))
                assert abs(gyro[i] - want) < 2e-3 * abs(want) + 5e-4, (n, i, gyro[i], want)
    if t > 1 - 1e-9 and n_fault is None:
        n_fault = n
assert len(G) == 21, len(G)
nofix = [k for k, gps in enumerate(G) if gps[12] == "1" and gps[13] == "0"]
fix = [k for k, gps in enumerate(G) if gps[12] == "3" and gps[13] == "10"]
lost = [12, 13, 14]                  # 1.2, 1.3, 1.4 s
assert nofix == list(range(5)) + lost and fix == [k for k in range(5, 21) if k not in lost], (nofix, fix)
print(f"px4 faults: az {-4 * F / m:.6f} -> {-3.75 * F / m:.6f} m/s^2 at t = 1 s (HIL_SENSOR {n_fault}); "
      f"rates at 1.1 s {[round(float(v), 5) for v in S[275][5:8]]} rad/s, worst {worst[0]:.1e} from tau/I t; "
      f"HIL_GPS without a fix 0..0.4 s (5) and over the outage 1.2..1.4 s (3), with one 0.5..2 s (13)")
PY
    ;;
  px4_spec)
    # What a PX4 scenario must say, each refused with exit 2 naming the key.
    mkdir -p "$tmp/etc/init.d-posix"
    check() {  # check NAME PATTERN YAML: exit 2 and the pattern in the message
      printf '%s\n' "$3" > "$tmp/$1.yaml"
      local rc=0; env -u QUADCOSIM_PX4_SITL "$bin" run "$tmp/$1.yaml" --out "$tmp/x" > "$tmp/$1.log" 2>&1 || rc=$?
      [ "$rc" -eq 2 ] && grep -q "$2" "$tmp/$1.log" || fail "$1: exit $rc $(cat "$tmp/$1.log")"
      grep -o "error.*" "$tmp/$1.log" | head -1 | cut -c1-180
    }
    ok="binary: $fake_px4, etc_dir: $tmp/etc"
    check nobin "controller.sitl.binary: missing.*QUADCOSIM_PX4_SITL" "controller: {sitl: {firmware: px4}}"
    check etc "controller.sitl.etc_dir: .*not PX4's ROMFS folder" "controller: {sitl: {firmware: px4, binary: $fake_px4, etc_dir: $tmp}}"
    check home "controller.sitl.home: is ArduPilot's" "controller: {sitl: {firmware: px4, $ok, home: '1,2,3,4'}}"
    check cpu "controller.sitl.cpu: is PX4's" "controller: {sitl: {binary: $fake, cpu: 0}}"
    check mode "mode: got 'guided', expected one of PX4's manual, altctl" "controller: {sitl: {firmware: px4, $ok, mission: [{mode: guided}]}}"
    check elsewhere "sensors: has no magnetometer.*World Magnetic Model" \
      "$(printf 'environment: {site: {latitude_deg: 10, longitude_deg: 20}}\ncontroller: {sitl: {firmware: px4, %s}}' "$ok")"
    check quiet "sensors.magnetometer.noise_sigma_uT: missing: PX4 takes a sensor whose readings repeat" \
      "$(printf 'sensors: {magnetometer: {field_uT: 48}}\ncontroller: {sitl: {firmware: px4, %s}}' "$ok")"
    printf 'BAD LINE HERE\n' > "$tmp/bad.parm"
    check parm "controller.sitl.params: .*bad.parm:1: expected NAME VALUE" "controller: {sitl: {firmware: px4, $ok, params: $tmp/bad.parm}}"
    # --controller sitl:px4:BINARY flies a file written for another controller (its sensors added).
    sed -e "/^controller:/,/^analysis:/{/^analysis:/!d}" "$here/fake_px4_open_loop.yaml" > "$tmp/paper.yaml"
    sed -i "s|^analysis:|controller:\n  sitl:\n    firmware: px4\n    etc_dir: $tmp/etc\n    params: $here/fake_px4_open_loop.parm\nanalysis:|" "$tmp/paper.yaml"
    rc=0; "$bin" run "$tmp/paper.yaml" --controller "sitl:px4:$fake_px4" --out "$tmp/flag" --judge none --no-plots \
      > "$tmp/flag.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail "--controller sitl:px4: exit $rc $(cat "$tmp/flag.log")"
    grep -q "firmware: px4" "$tmp/flag/scenario.yaml" || fail "scenario.yaml: $(cat "$tmp/flag/scenario.yaml")"
    echo "px4 spec: 8 refusals named; --controller sitl:px4:BINARY flew"
    ;;
  real_px4)
    # PX4's SITL build (QUADCOSIM_PX4_SITL) flies scenarios/sitl/px4_takeoff_waypoint_land.yaml twice:
    # the same trajectory.csv bytes; it holds 10 m, reaches the waypoint (10, 5, 10), lands and disarms.
    if [ -z "${QUADCOSIM_PX4_SITL:-}" ] || [ ! -x "$QUADCOSIM_PX4_SITL" ]; then
      echo "SKIPPED: QUADCOSIM_PX4_SITL does not name PX4's SITL executable (build/px4_sitl_default/bin/px4, docs/sitl.md)"
      exit 77
    fi
    for n in r1 r2; do
      rc=0; "$bin" run "$src/scenarios/sitl/px4_takeoff_waypoint_land.yaml" --out "$tmp/$n" --judge none \
        > "$tmp/$n.log" 2>&1 || rc=$?
      [ "$rc" -eq 0 ] || fail "$n exited $rc: $(tail -5 "$tmp/$n.log")"
    done
    cmp "$tmp/r1/trajectory.csv" "$tmp/r2/trajectory.csv" || fail "two runs of the same firmware differ"
    "$py" - "$tmp/r1/trajectory.csv" <<'PY' || fail "mission"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
armed = [float(r["t"]) for r in rows if r["out.armed"] == "1"]
assert armed, "never armed"
hold = [float(r["z"]) for r in rows if 25 <= float(r["t"]) <= 40]
assert min(hold) > 9.5 and max(hold) < 10.5, (min(hold), max(hold))
wp = [math.hypot(float(r["x"]) - 10, float(r["y"]) - 5) for r in rows if 52 <= float(r["t"]) <= 65]
assert max(wp) < 0.5, max(wp)
last = rows[-1]
assert float(last["z"]) < 0.05 and last["out.armed"] == "0", (last["z"], last["out.armed"])
print(f"real px4: armed at {armed[0]:.2f} s, 10 m held within [{min(hold):.3f}, {max(hold):.3f}] m, "
      f"waypoint within {max(wp):.3f} m, landed and disarmed at {armed[-1]:.2f} s; two runs identical")
PY
    ;;
  *) echo "unknown case $case_name"; exit 2 ;;
esac
