#!/usr/bin/env bash
# Co-simulation over DDS with real processes. Usage: dds_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# Every case runs on its own ROS_DOMAIN_ID with localhost-only discovery, and ends every process it
# started (trap), also on failure.
bin="$1"; src="$2"; stranger="${5:-}"  # tests/stranger, for the stranger_* cases
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
paper="$src/scenarios/paper"
# Two metrics.json hold the same judgement (besides their provenance: transport, command line).
same_metrics() { /usr/bin/python3 "$src/tests/lib/same_metrics.py" "$@"; }
# shellcheck source=../lib/same_recording.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/same_recording.sh"

identical() {  # in-process and DDS lockstep give the same bytes
  local s="$1"
  "$bin" run "$paper/$s.yaml" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
  "$bin" run "$paper/$s.yaml" --out "$tmp/dds" --no-plots --transport dds > "$tmp/dds.log" 2>&1 \
    || fail "DDS run failed"
  cmp "$tmp/in/trajectory.csv" "$tmp/dds/trajectory.csv" || fail "trajectories differ"
  same_metrics "$tmp/in/metrics.json" "$tmp/dds/metrics.json" || fail "metrics differ"
  same_recording "$tmp/in/run.mcap" "$tmp/dds/run.mcap" || fail "MCAP recordings differ"
  # Each records how it flew.
  /usr/bin/python3 - "$tmp/in" "$tmp/dds" <<'PY' || fail "the transport is not recorded"
import json, sys, yaml
for run, transport in zip(sys.argv[1:], ("inproc", "dds")):
    p = json.load(open(run + "/metrics.json"))["provenance"]
    assert p["transport"] == transport and p["clock"] == "lockstep", (run, p["transport"])
    assert yaml.safe_load(open(run + "/metadata.yaml"))["quadcosim_provenance"] == p, run
PY
  [ "$(wc -l < "$tmp/dds/trajectory.csv")" -gt 500 ] || fail "trajectory too short"
}

# Every scenario in scenarios/, in-process and over DDS lockstep: the same bytes (single vehicles:
# trajectory, metrics, MCAP; swarms: every recorded vehicle's trajectory and metrics and the final
# states). With QUADCOSIM_REFERENCE_DIR set (REF/<scenario name>/ from an earlier build's
# `run --no-plots`), the in-process outputs are compared with it too: before/after a change.
identical_all() {
  local files=("trajectory.csv" "metrics.json" "run.mcap" "vehicles.csv") n=0
  for s in "$src"/scenarios/*/*.yaml; do
    # scenarios/sitl fly ArduPilot's SITL build, px4_* PX4's: only where QUADCOSIM_ARDUPILOT_SITL /
    # QUADCOSIM_PX4_SITL names it (docs/sitl.md).
    [[ "$s" == */scenarios/sitl/px4_* && -z "${QUADCOSIM_PX4_SITL:-}" ]] && continue
    [[ "$s" == */scenarios/sitl/* && "$s" != */scenarios/sitl/px4_* && -z "${QUADCOSIM_ARDUPILOT_SITL:-}" ]] && continue
    local name; name="$(basename "$s" .yaml)"
    s="${s#"$src/"}"  # run from the source folder: metrics.json names the scenario as given
    cd "$src"
    "$bin" run "$s" --out "$tmp/in/$name" --no-plots > "$tmp/in_$name.log" 2>&1 || fail "$name: in-process run failed"
    "$bin" run "$s" --out "$tmp/dds/$name" --no-plots --transport dds > "$tmp/dds_$name.log" 2>&1 \
      || fail "$name: DDS run failed"
    local compared=0
    while IFS= read -r f; do
      local rel="${f#"$tmp/in/$name/"}"
      case " ${files[*]} " in *" $(basename "$rel") "*) ;; *) continue ;; esac
      local same=cmp
      [ "$(basename "$rel")" = metrics.json ] && same=same_metrics
      [ "$(basename "$rel")" = run.mcap ] && same=same_recording
      $same "$f" "$tmp/dds/$name/$rel" || fail "$name: $rel differs over DDS"
      if [ -n "${QUADCOSIM_REFERENCE_DIR:-}" ]; then
        $same "$f" "$QUADCOSIM_REFERENCE_DIR/$name/$rel" || fail "$name: $rel differs from the reference"
      fi
      compared=$((compared + 1))
    done < <(find "$tmp/in/$name" -type f | sort)
    [ "$compared" -ge 2 ] || fail "$name: only $compared files compared"
    n=$((n + 1))
  done
  [ "$n" -ge 9 ] || fail "only $n scenarios found"
  echo "$n scenarios identical in-process and over DDS${QUADCOSIM_REFERENCE_DIR:+ and to the reference}"
}

# A stranger publishing on the run's topics before and during `run --transport dds`: the trajectory,
# metrics and the run's own recorded messages are those of the in-process run, the plant counts what
# it ignored. Usage: with_stranger MODE (stranger.cpp: commands | sensors).
with_stranger() {
  "$bin" run "$paper/altitude_step.yaml" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
  "$stranger" "$1" 40 > "$tmp/stranger.out" 2> "$tmp/stranger.log" &
  local spid=$!
  pids+=("$spid")
  sleep 1  # the stranger is on the domain first: its messages are there when the run starts
  "$bin" run "$paper/altitude_step.yaml" --out "$tmp/dds" --no-plots --transport dds > "$tmp/dds.log" 2>&1 \
    || fail "DDS run with a stranger failed"
  kill "$spid" 2> /dev/null || true
  cmp "$tmp/in/trajectory.csv" "$tmp/dds/trajectory.csv" || fail "the stranger changed the trajectory"
  same_metrics "$tmp/in/metrics.json" "$tmp/dds/metrics.json" || fail "the stranger changed the metrics"
}

# Message count of TOPIC in a run folder's metadata.yaml.
bag_count() {
  /usr/bin/python3 - "$1/metadata.yaml" "$2" <<'PY'
import sys, yaml
info = yaml.safe_load(open(sys.argv[1]))["rosbag2_bagfile_information"]
print(sum(t["message_count"] for t in info["topics_with_message_count"] if t["topic_metadata"]["name"] == sys.argv[2]))
PY
}

case "$case_name" in
  stranger_commands)
    with_stranger commands
    grep -Eq "foreign \(not the controller's writers\) [1-9][0-9]*" "$tmp/dds.log" ||
      fail "the plant counted no foreign commands: $(grep 'plant: done' "$tmp/dds.log")"
    grep -q "stale 0;" "$tmp/dds.log" || fail "stale commands: $(grep 'plant: done' "$tmp/dds.log")"
    ;;
  stranger_sensors)
    with_stranger sensors
    grep -Eq "controller: [1-9][0-9]* sensor samples from writers other than the plant's ignored" "$tmp/dds.log" ||
      fail "the controller counted no foreign samples"
    # Every status the run's own controller published is recorded, beside the stranger's.
    own=$(bag_count "$tmp/in" /drone/controller_status)
    got=$(bag_count "$tmp/dds" /drone/controller_status)
    [ "$own" -gt 700 ] && [ "$got" -gt "$own" ] ||
      fail "run.mcap holds $got controller statuses; the run's own controller published $own"
    ;;
  leftover_controller)  # a controller of an earlier run still alive on the domain: no pairing token
    "$bin" run "$paper/altitude_step.yaml" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
    "$bin" controller --scenario "$paper/altitude_step.yaml" > "$tmp/leftover.log" 2>&1 &
    pids+=($!)
    sleep 1
    "$bin" run "$paper/altitude_step.yaml" --out "$tmp/dds" --no-plots --transport dds > "$tmp/dds.log" 2>&1 \
      || fail "DDS run beside a leftover controller failed"
    cmp "$tmp/in/trajectory.csv" "$tmp/dds/trajectory.csv" || fail "the leftover controller changed the trajectory"
    grep -Eq "foreign \(not the controller's writers\) [1-9][0-9]*" "$tmp/dds.log" ||
      fail "the leftover controller's commands were not counted as foreign"
    ;;
  answer_every_sample)  # a controller answering each sensor sample: lockstep stops and says so
    "$stranger" answer_every_sample 30 > "$tmp/controller.out" 2> "$tmp/controller.log" &
    pids+=($!)
    set +e
    timeout 60 "$bin" plant --scenario "$paper/altitude_step.yaml" --timeout 5 > "$tmp/plant.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 4 ] || fail "plant exit $rc, expected 4 (docs/reliability.md): $(cat "$tmp/plant.log")"
    grep -Eq "the controller sent [0-9]+ commands for [0-9]+ control periods, where lockstep expects one each" \
      "$tmp/plant.log" ||
      fail "no reason given: $(cat "$tmp/plant.log")"
    ;;
  identical_all_scenarios) identical_all ;;
  identical_altitude) identical altitude_step ;;
  identical_roll) identical roll_step ;;
  identical_pitch) identical pitch_step ;;
  identical_yaw) identical yaw_step ;;
  identical_midrun_schedule)  # changes mid-run (one between controller ticks) through parameter services
    paper="$src/tests/dds"
    identical midrun_schedule
    ;;
  identical_realism)  # sensor noise, latency, rates, wind, gusts, drag, a rotor fault: the same bytes
    paper="$src/tests/dds"
    identical realism_lockstep
    grep -q '"hold"' "$tmp/dds/metrics.json" || fail "no hold figures"
    # The noise is really drawn from the seed: another seed flies another path.
    sed 's/^seed: 2024$/seed: 2025/' "$paper/realism_lockstep.yaml" > "$tmp/seed2025.yaml"
    "$bin" run "$tmp/seed2025.yaml" --out "$tmp/other" --no-plots > "$tmp/other.log" 2>&1 || fail "seed 2025 run failed"
    if cmp -s "$tmp/in/trajectory.csv" "$tmp/other/trajectory.csv"; then fail "the seed changed nothing"; fi
    ;;

  realtime_altitude|realtime_roll|realtime_pitch|realtime_yaw)  # the paper's setup: wall-clock paced
    # The accepted bands of the scenario must hold in real time too (exit 0 = every criterion met).
    # Altitude at 1x; the attitude steps at 3x to keep the suite short (both nodes scale their
    # timers; 3x is far from what the machine can do).
    s="${case_name#realtime_}_step"
    factor=3; [ "$s" = altitude_step ] && factor=1
    timeout 120 "$bin" run "$paper/$s.yaml" --out "$tmp/rt" --no-plots --transport dds --realtime \
      --rate-factor "$factor" > "$tmp/rt.log" 2>&1 || fail "real-time run missed the paper's bands"
    grep -q "real-time mode" "$tmp/rt.log" || fail "not run in real time"
    ;;

  no_controller)  # lockstep with nobody to answer: a diagnostic and a non-zero exit, no hang
    set +e
    timeout 30 "$bin" plant --scenario "$paper/altitude_step.yaml" --timeout 1 > "$tmp/plant.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 4 ] || fail "expected exit 4, got $rc"
    grep -q "no controller on /drone/motor_commands" "$tmp/plant.log" || fail "no diagnostic"
    grep -q "ROS_DOMAIN_ID $ROS_DOMAIN_ID" "$tmp/plant.log" || fail "diagnostic does not name the domain"
    ;;

  controller_lost_abort|controller_lost_hold)  # the controller dies mid-run
    policy="${case_name#controller_lost_}"
    "$bin" controller --scenario "$paper/altitude_step.yaml" > "$tmp/controller.log" 2>&1 &
    cpid=$!; pids+=("$cpid")
    "$bin" plant --scenario "$paper/altitude_step.yaml" --duration 1000 --timeout 1 --on-timeout "$policy" \
      --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1 &
    ppid=$!; pids+=("$ppid")
    for _ in $(seq 100); do [ -s "$tmp/t.csv" ] && break; sleep 0.05; done
    sleep 0.3
    kill -KILL "$cpid"
    set +e
    timeout 120 tail --pid="$ppid" -f /dev/null
    wait "$ppid"; rc=$?
    set -e
    grep -q "lockstep timeout: no motor command on /drone/motor_commands for tick" "$tmp/plant.log" \
      || fail "no timeout diagnostic"
    # A SIGKILLed writer stays matched until Cyclone's participant lease (10 s) runs out.
    grep -Eq "matched command writers: [0-9]+; policy: $policy" "$tmp/plant.log" || fail "diagnostic lacks matches/policy"
    if [ "$policy" = abort ]; then
      [ "$rc" -eq 4 ] || fail "abort policy: expected exit 4, got $rc"
    else
      [ "$rc" -eq 0 ] || fail "hold policy: expected exit 0, got $rc"
      grep -q "100000 ticks" "$tmp/plant.log" || fail "unexpected run length"
      [ "$(wc -l < "$tmp/t.csv")" -eq 100002 ] || fail "hold policy did not finish the run"
    fi
    ;;

  pinned)  # plant and controller each on its own CPU (--cpus): every thread there, the same bytes
    # The first two CPUs this test may use (one, twice, on a single-CPU machine).
    read -r want_p want_c < <(/usr/bin/python3 -c '
import os
c = sorted(os.sched_getaffinity(0))
print(c[0], c[1] if len(c) > 1 else c[0])')
    "$bin" run "$paper/roll_step.yaml" --out "$tmp/in" --no-plots > /dev/null
    "$bin" controller --scenario "$paper/roll_step.yaml" --cpus "$want_c" > "$tmp/c.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$paper/roll_step.yaml" --cpus "$want_p" --record "$tmp/p.csv" > "$tmp/p.log" 2>&1 \
      || fail "plant failed"
    cmp "$tmp/in/trajectory.csv" "$tmp/p.csv" || fail "differs from the in-process run"
    # Every thread of the controller (its own and Cyclone's) is on its CPU only.
    for status in /proc/"${pids[-1]}"/task/*/status; do
      allowed=$(sed -n 's/^Cpus_allowed_list:[[:space:]]*//p' "$status")
      [ "$allowed" = "$want_c" ] || fail "controller thread $status allowed on '$allowed', expected '$want_c'"
    done
    kill -TERM "${pids[-1]}"; wait "${pids[-1]}" 2>/dev/null || true  # one controller on the domain
    # `run --pin` does the same for its two child processes.
    "$bin" run "$paper/roll_step.yaml" --transport dds --pin --out "$tmp/r" --no-plots > "$tmp/run.log" 2>&1 \
      || fail "run --transport dds --pin failed"
    cmp "$tmp/in/trajectory.csv" "$tmp/r/trajectory.csv" || fail "run --pin differs from the in-process run"
    if [ "$want_p" != "$want_c" ]; then
      grep -q "^plant: on CPU(s) $want_p only" "$tmp/run.log" || fail "run --pin: plant not on CPU $want_p"
      grep -q "^controller: on CPU(s) $want_c only" "$tmp/run.log" || fail "run --pin: controller not on CPU $want_c"
    fi
    ;;

  packed_sends)  # lockstep: a writer's sample of the tick between two control ticks goes out in one datagram with
    # the next control tick's (docs/performance.md): 10 s of the paper's 100 Hz sensors (Pose, Velocity, Imu: 3000
    # samples, 500 control periods) take about 1500 datagrams, not 3000; counted at the plant's send calls.
    command -v strace > /dev/null || { echo "SKIP: strace is not installed (it counts the plant's datagrams)"; exit 77; }
    "$bin" controller --scenario "$paper/altitude_step.yaml" > "$tmp/c.log" 2>&1 &
    pids+=($!)
    if ! strace -f -qq -e trace=sendmsg,sendto,sendmmsg -o "$tmp/sends.txt" \
      "$bin" plant --scenario "$paper/altitude_step.yaml" --duration 10 > "$tmp/p.log" 2>&1; then
      if grep -q "ptrace\|Operation not permitted" "$tmp/p.log"; then
        echo "SKIP: strace cannot trace here: $(head -1 "$tmp/p.log")"; exit 77
      fi
      fail "plant failed"
    fi
    grep -q "1000 ticks" "$tmp/p.log" || fail "unexpected run length"
    sends=$(grep -c "^[0-9]* *send" "$tmp/sends.txt")
    echo "the plant's datagrams for 10 s (3000 sensor samples, 500 control periods; status and discovery too): $sends"
    [ "$sends" -lt 2000 ] || fail "$sends datagrams: the sensor samples between control ticks are not packed"
    ;;

  status_when_recorded)  # the controller's status goes on the wire only to a plant that records it
    # (docs/performance.md): 10 s, 500 control periods. A plant without --record reads no status, so the
    # controller sends about one datagram a period (its command); with --record the status too (awaited:
    # its columns are in the file). Counted at the controller's send calls, discovery included.
    command -v strace > /dev/null || { echo "SKIP: strace is not installed (it counts the controller's datagrams)"; exit 77; }
    declare -A sends
    for mode in bare recorded; do
      args=()
      [ "$mode" = recorded ] && args=(--record "$tmp/p.csv")
      strace -f -qq -e trace=sendmsg,sendto,sendmmsg -o "$tmp/sends_$mode.txt" \
        "$bin" controller --scenario "$paper/altitude_step.yaml" > "$tmp/c_$mode.log" 2>&1 &
      spid=$!
      pids+=("$spid")
      if ! "$bin" plant --scenario "$paper/altitude_step.yaml" --duration 10 "${args[@]}" > "$tmp/p_$mode.log" 2>&1; then
        if grep -q "ptrace\|Operation not permitted" "$tmp/c_$mode.log"; then
          echo "SKIP: strace cannot trace here: $(head -1 "$tmp/c_$mode.log")"; exit 77
        fi
        fail "plant ($mode) failed"
      fi
      grep -q "1000 ticks" "$tmp/p_$mode.log" || fail "unexpected run length ($mode)"
      pkill -INT -P "$spid" 2>/dev/null || true  # the controller under strace; strace ends with it
      wait "$spid" 2>/dev/null || true
      sends[$mode]=$(grep -c "^[0-9]* *send" "$tmp/sends_$mode.txt")
    done
    echo "the controller's datagrams for 500 control periods: plant not recording ${sends[bare]}, recording ${sends[recorded]}"
    [ "${sends[bare]}" -lt 800 ] || fail "${sends[bare]} datagrams to a plant that records nothing: the status is still sent"
    [ "${sends[recorded]}" -gt 950 ] || fail "${sends[recorded]} datagrams to a recording plant: no status each period"
    head -1 "$tmp/p.csv" | grep -q "out\.error\.z" || fail "the recording has no controller columns"
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "out.error.z") c = i } NR > 3 && $c == "nan" { n++ }
      END { exit n > 0 }' "$tmp/p.csv" || fail "controller columns missing in recorded rows"
    ;;

  sensor_qos)  # best-effort sensor topics (ROS sensor-data QoS) on both sides: still the same bytes
    "$bin" run "$paper/roll_step.yaml" --out "$tmp/in" --no-plots > /dev/null
    "$bin" controller --scenario "$paper/roll_step.yaml" --sensor-qos > "$tmp/c.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$paper/roll_step.yaml" --sensor-qos --record "$tmp/p.csv" > "$tmp/p.log" 2>&1 \
      || fail "plant failed"
    cmp "$tmp/in/trajectory.csv" "$tmp/p.csv" || fail "differs from the in-process run"
    # A reliable reader does not match a best-effort writer: a default controller is not found.
    "$bin" controller --scenario "$paper/roll_step.yaml" --namespace /other > "$tmp/c2.log" 2>&1 &
    pids+=($!)
    set +e
    "$bin" plant --scenario "$paper/roll_step.yaml" --namespace /other --sensor-qos --timeout 2 > "$tmp/p2.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 4 ] || fail "QoS mismatch should leave the plant without a controller (exit 4), got $rc"
    grep -q "no controller" "$tmp/p2.log" || fail "no diagnostic for the QoS mismatch"
    ;;

  record)  # quadcosim record over DDS next to a real-time plant; read back by the MCAP reference reader
    "$bin" plant --realtime --duration 4 > "$tmp/plant.log" 2>&1 &
    pids+=($!)
    "$bin" record --out "$tmp/bag/rec.mcap" --topics /drone/Pose /clock --duration 3 > "$tmp/rec.log" 2>&1 \
      || fail "record failed"
    [ -s "$tmp/bag/metadata.yaml" ] || fail "no metadata.yaml beside the recording"
    if command -v node > /dev/null && [ -d "$src/tools/mcap_verify/node_modules" ]; then
      node "$src/tools/mcap_verify/verify.mjs" "$tmp/bag/rec.mcap" > "$tmp/summary.json" || fail "unreadable MCAP"
      /usr/bin/python3 - "$tmp/summary.json" <<'PY' || fail "recording content"
import json, sys
ch = json.load(open(sys.argv[1]))["channels"]
assert set(ch) == {"/drone/Pose", "/clock"}, sorted(ch)
n = ch["/drone/Pose"]["last"]["sequence"]
assert 100 <= n <= 401, n  # ~3 s of a 100 Hz real-time plant
assert ch["/drone/Pose"]["last"]["message"]["header"]["frame_id"] == "world"
PY
    fi
    set +e
    "$bin" record --out "$tmp/x.mcap" --topics /nope --duration 1 > "$tmp/bad.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 2 ] && grep -q "cannot record '/nope'" "$tmp/bad.log" || fail "unknown topic not refused"
    ;;

  two_namespaces)  # two vehicles on one domain, /uav1 and /uav2: no cross-talk
    "$bin" run "$paper/altitude_step.yaml" --out "$tmp/in1" --no-plots > /dev/null
    "$bin" run "$paper/roll_step.yaml" --out "$tmp/in2" --no-plots > /dev/null
    "$bin" controller --scenario "$paper/altitude_step.yaml" --namespace /uav1 > "$tmp/c1.log" 2>&1 &
    pids+=($!)
    "$bin" controller --scenario "$paper/roll_step.yaml" --namespace /uav2 > "$tmp/c2.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$paper/altitude_step.yaml" --namespace /uav1 --record "$tmp/p1.csv" > "$tmp/p1.log" 2>&1 &
    p1=$!; pids+=("$p1")
    "$bin" plant --scenario "$paper/roll_step.yaml" --namespace /uav2 --record "$tmp/p2.csv" > "$tmp/p2.log" 2>&1 &
    p2=$!; pids+=("$p2")
    wait "$p1" || fail "plant /uav1 failed"
    wait "$p2" || fail "plant /uav2 failed"
    cmp "$tmp/in1/trajectory.csv" "$tmp/p1.csv" || fail "/uav1 differs from its in-process run"
    cmp "$tmp/in2/trajectory.csv" "$tmp/p2.csv" || fail "/uav2 differs from its in-process run"
    ;;

  topic_tools)  # quadcosim topic list/echo/hz against a real-time plant (on the ground, 100 Hz)
    # The plant runs longer than the checks need (about 5 s): the trap ends it.
    "$bin" plant --realtime --duration 10 > "$tmp/plant.log" 2>&1 &
    pids+=($!)
    "$bin" topic list -t --wait 2 > "$tmp/list.log" 2>&1 || fail "topic list failed"
    for line in "/drone/Pose [geometry_msgs/msg/PoseStamped]" "/drone/Imu [sensor_msgs/msg/Imu]" \
                "/clock [rosgraph_msgs/msg/Clock]"; do
      grep -qxF "$line" "$tmp/list.log" || fail "topic list -t lacks '$line'"
    done
    "$bin" topic list --wait 0.5 > "$tmp/list_plain.log" 2>&1 || fail "topic list (no -t) failed"
    grep -qx "/drone/Velocity" "$tmp/list_plain.log" || fail "topic list (no -t) lacks /drone/Velocity"
    timeout 30 "$bin" topic echo /drone/Pose --count 2 > "$tmp/echo.log" 2>&1 || fail "topic echo failed"
    [ "$(grep -cx -- '---' "$tmp/echo.log")" -eq 2 ] || fail "expected two messages"
    [ "$(grep -cx '  frame_id: world' "$tmp/echo.log")" -eq 2 ] || fail "expected frame_id: world twice"
    grep -qx '    w: 1.0' "$tmp/echo.log" || fail "no orientation w: 1.0"
    timeout 30 "$bin" topic hz /drone/Imu --duration 2 > "$tmp/hz.log" 2>&1 || fail "topic hz failed"
    rate="$(awk '/^average rate:/ { r = $3 } END { print r }' "$tmp/hz.log")"
    [ -n "$rate" ] || fail "topic hz printed no rate"
    awk -v r="$rate" 'BEGIN { exit !(r >= 90 && r <= 110) }' || fail "rate $rate Hz outside 90-110 Hz"
    grep -q "window: " "$tmp/hz.log" || fail "no window in the hz report"
    set +e
    "$bin" topic echo /drone/nothing --wait 0.5 > "$tmp/missing.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 2 ] || fail "unknown topic: expected exit 2, got $rc"
    grep -q "topic /drone/nothing not found on ROS_DOMAIN_ID $ROS_DOMAIN_ID" "$tmp/missing.log" \
      || fail "unknown topic: no clear error"
    ;;

  param_set_climbs)  # ROS 2 parameter services: `quadcosim param set` raises z_des of a real-time flight
    "$bin" controller --realtime > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    # Also waits for the node to come up (--timeout 5 s by default).
    "$bin" param get /attitude_controller z_des > "$tmp/get0.log" 2> "$tmp/get0.err.log" || fail "param get (before) failed"
    grep -qx "Double value is: 0.0" "$tmp/get0.log" || fail "z_des does not start at 0.0: $(cat "$tmp/get0.log")"
    "$bin" plant --realtime --duration 8 --record "$tmp/t.csv" > "$tmp/plant.log" 2>&1 &
    ppid=$!; pids+=("$ppid")
    sleep 1
    "$bin" param set /attitude_controller z_des 3.0 > "$tmp/set.log" 2>&1 || fail "param set failed"
    grep -qx "Set parameter successful" "$tmp/set.log" || fail "param set: unexpected output"
    "$bin" param get /attitude_controller z_des > "$tmp/get.log" 2>&1 || fail "param get failed"
    grep -qx "Double value is: 3.0" "$tmp/get.log" || fail "param get: expected 3.0, got $(cat "$tmp/get.log")"
    # A refusal: non-zero exit and the table's reason.
    set +e
    "$bin" param set /attitude_controller z_des high > "$tmp/refused.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 1 ] || fail "refused set: expected exit 1, got $rc"
    grep -q "Setting parameter failed: z_des must be a number, got 'high'" "$tmp/refused.log" \
      || fail "refused set: no reason"
    timeout 60 tail --pid="$ppid" -f /dev/null || fail "plant did not finish"
    wait "$ppid" || fail "plant failed"
    z_end="$(tail -1 "$tmp/t.csv" | cut -d, -f4)"
    z_start="$(sed -n 2p "$tmp/t.csv" | cut -d, -f4)"
    awk -v z="$z_start" 'BEGIN { exit !(z < 0.01) }' || fail "did not start on the ground (z = $z_start)"
    awk -v z="$z_end" 'BEGIN { exit !(z > 2.0) }' || fail "did not climb: z at the end = $z_end"
    ;;

  *) fail "unknown case" ;;
esac
echo "ok [$case_name]"
