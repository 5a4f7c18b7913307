#!/usr/bin/env bash
# quadcosim against real ROS 2 (Jazzy, rmw_cyclonedds_cpp): the rclcpp and rclpy controllers of this
# folder, unmodified ROS 2 nodes that step from a timer on ROS time, flown by `quadcosim plant` in
# lockstep; and the ros2 command line on quadcosim's nodes.
#
#   ros2_cases.sh QUADCOSIM SOURCE_DIR CASE DOMAIN_ID WORK_DIR
#   CASE: rclcpp_lockstep | rclcpp_no_clock_thread | rclpy_lockstep | cli | rclpy_pose_callback |
#         rclpy_timer_100hz | rclpy_multithreaded | rclcpp_multithreaded | rclcpp_pose_callback |
#         rclpy_slow_steps | rclcpp_labelled
#
# Needs a ROS 2 installation: one already sourced (ROS_DISTRO set, `ros2` on PATH), or the setup
# file named by QUADCOSIM_ROS2_SETUP (e.g. /opt/ros/jazzy/setup.bash), with rclcpp, rclpy, ros2cli
# and rmw_cyclonedds_cpp. Without it the case reports SKIPPED (exit 77) and says why. The rclcpp
# controller is built in WORK_DIR/rclcpp_controller with the installation's CMake packages (once,
# under a lock, for every case).
#
# What each case checks, with numbers it did not produce:
#  - every control step of the controller (its log: now, and the stamps of the Pose, Velocity and
#    Imu it used) used the samples of its own tick: the three stamps equal the ROS time of the step;
#    steps come every 20 ms from t = 0.02 s on, 750 in the 15 s of the paper's altitude step;
#  - repeated runs give byte-identical trajectory.csv (20 for rclcpp), and the rclcpp and rclpy
#    controllers, which compute the same law in the same order, give the same bytes as each other;
#  - the flight is the altitude step: z(15 s) within 1 % of z_des = 10 m (PD: wn 1.43 rad/s, zeta
#    0.48, settled to 2 % by ~6 s);
#  - nothing in the ROS 2 processes' output is a warning or an error (rclcpp's INFO line on SIGTERM
#    is not);
#  - node shapes (a Pose callback publishing, a 100 Hz timer, steps slower than the plant's repeat):
#    every run refused with exit 4 and the message naming the shape, or every run flown as above with
#    the same bytes; never exit 0 with a timing-dependent flight;
#  - a 2-thread MultiThreadedExecutor whose node labels its commands with the stamps it used: each run
#    flown with the single-threaded node's bytes, or refused (exit 4) at the step the node's own log
#    shows on older samples.
set -euo pipefail
QC="$1" SRC="$2" case_arg="$3" DOMAIN="$4" WORK="$5"

skip() { echo "SKIPPED: $*"; exit 77; }
if [ -n "${QUADCOSIM_ROS2_SETUP:-}" ]; then
  [ -f "$QUADCOSIM_ROS2_SETUP" ] || skip "QUADCOSIM_ROS2_SETUP=$QUADCOSIM_ROS2_SETUP is not a file"
  set +u
  # shellcheck disable=SC1090
  source "$QUADCOSIM_ROS2_SETUP"
  set -u
fi
command -v ros2 > /dev/null 2>&1 && [ -n "${AMENT_PREFIX_PATH:-}" ] ||
  skip "no ROS 2 installation: source one (e.g. /opt/ros/jazzy/setup.bash) or set QUADCOSIM_ROS2_SETUP"
has_package() {
  local p
  for p in ${AMENT_PREFIX_PATH//:/ }; do
    [ -e "$p/share/ament_index/resource_index/packages/$1" ] && return 0
  done
  return 1
}
for p in rclcpp rclpy rmw_cyclonedds_cpp ros2topic ros2param ros2node; do
  has_package "$p" || skip "the ROS 2 installation has no $p"
done
export RMW_IMPLEMENTATION=rmw_cyclonedds_cpp
# The Python the installation's tools run on (a python3 earlier on PATH may lack its modules).
ROS_PY=$(head -1 "$(command -v ros2)" | sed -n 's/^#! *//p')
[ -x "${ROS_PY%% *}" ] || ROS_PY=python3
# shellcheck source=../lib/process_case.sh
source "$SRC/tests/lib/process_case.sh" "ros2.$case_arg" "$DOMAIN"

# The rclcpp controller, built once for all cases (they may run in parallel).
CTL_CPP="$WORK/rclcpp_controller/attitude_controller"
build_rclcpp_controller() {
  mkdir -p "$WORK"
  (
    flock 9
    if [ ! -x "$CTL_CPP" ] || [ "$SRC/tests/ros2/rclcpp_controller/src/attitude_controller.cpp" -nt "$CTL_CPP" ]; then
      # ament's CMake runs Python scripts that need the installation's modules (catkin_pkg): its Python.
      cmake -S "$SRC/tests/ros2/rclcpp_controller" -B "$WORK/rclcpp_controller" -DCMAKE_BUILD_TYPE=Release \
        -DPython3_EXECUTABLE="${ROS_PY%% *}" > "$WORK/build.log" 2>&1 &&
        cmake --build "$WORK/rclcpp_controller" -j2 >> "$WORK/build.log" 2>&1 || { cat "$WORK/build.log"; exit 1; }
    fi
  ) 9> "$WORK/build.lock" || fail "building tests/ros2/rclcpp_controller failed"
}
CTL_PY="$SRC/tests/ros2/rclpy_controller/attitude_controller.py"
SCENARIO="$SRC/scenarios/paper/altitude_step.yaml"

# No warnings or errors in a ROS 2 process's output (FILE): rclcpp's and rclpy's log lines and
# Python tracebacks.
no_warnings() {
  if grep -E "\[(WARN|ERROR|FATAL)\]|Traceback|[Ff]ailed|INVALID" "$1"; then fail "$2 printed warnings or errors (above)"; fi
}

# fly N CONTROLLER... [--ros-args ARGS...]: one paper altitude step (15 s) in lockstep, whatever its
# outcome; leaves run N's trajectory.csv, the controller's step log, both outputs, the plant's stats
# and exit code (rc) in $tmp/runN/.
fly() {
  local n="$1"
  shift
  local d="$tmp/run$n"
  mkdir -p "$d"
  local ros_args=()
  [[ " $* " == *" --ros-args "* ]] || ros_args=(--ros-args)
  "$@" "${ros_args[@]}" -p use_sim_time:=true -p log_file:="$d/steps.log" > "$d/controller.out" 2>&1 &
  local ctl=$!
  pids+=("$ctl")
  local rc=0
  "$QC" plant --scenario "$SCENARIO" --schedule-via /attitude_controller --record "$d/trajectory.csv" \
    --stats "$d/stats.json" --timeout 30 > "$d/plant.out" 2>&1 || rc=$?
  # SIGTERM, then SIGKILL after 5 s: an rclpy node stopped while the plant it answered was gone has
  # been seen to hang in its shutdown (every thread in a futex wait).
  kill -TERM "$ctl" 2>/dev/null || true
  local _
  for _ in $(seq 50); do
    kill -0 "$ctl" 2>/dev/null || break
    sleep 0.1
  done
  kill -KILL "$ctl" 2>/dev/null || true
  wait "$ctl" 2>/dev/null || true
  echo "$rc" > "$d/rc"
}

# lockstep_run N CONTROLLER...: fly, and check run N (check_flown).
lockstep_run() {
  fly "$@"
  check_flown "$1"
}

# check_flown N: run N exited 0 on the ROS-time protocol, without warnings, every step on its own
# tick's samples, z(15 s) = 10 m.
check_flown() {
  local n="$1" d="$tmp/run$1"
  local rc
  rc=$(cat "$d/rc")
  [ "$rc" = 0 ] || { cat "$d/plant.out"; fail "run $n: plant exited with $rc"; }
  grep -q "lockstep with /attitude_controller on ROS time" "$d/plant.out" ||
    { cat "$d/plant.out"; fail "run $n: the plant did not choose the ROS-time protocol"; }
  if grep -i "warning" "$d/plant.out"; then fail "run $n: the plant warned (above)"; fi
  no_warnings "$d/controller.out" "run $n's controller"
  # Every step used its own tick's samples; a step every 20 ms from 0.02 s to 15 s.
  awk -v run="$n" '
    { if ($1 != $2 || $1 != $3 || $1 != $4) { printf "run %s: the step at %s ns used samples of %s/%s/%s ns\n", run, $1, $2, $3, $4; bad++ }
      if ($1 != NR * 20000000) { printf "run %s: step %d at %s ns, expected %.0f\n", run, NR, $1, NR * 20000000; bad++ } }
    END { if (NR != 750) { printf "run %s: %d steps, expected 750\n", run, NR; bad++ } exit bad > 0 }' "$d/steps.log" ||
    fail "run $n: the controller's steps did not see their own ticks' samples"
  # The altitude step reached 10 m (z is column 4 of trajectory.csv).
  tail -1 "$d/trajectory.csv" | awk -F, '{ exit !($4 > 9.9 && $4 < 10.1) }' ||
    fail "run $n: z(15 s) = $(tail -1 "$d/trajectory.csv" | cut -d, -f4), expected 10 m within 1 %"
  "$ROS_PY" -c 'import json,sys; print("run %s: %.1fx real time" % (sys.argv[2], json.load(open(sys.argv[1]))["real_time_factor"]))' \
    "$d/stats.json" "$n"
}

# same_bytes FIRST LAST [REFERENCE]: runs FIRST..LAST gave the same trajectory.csv (as REFERENCE's).
same_bytes() {
  local ref="${3:-$tmp/run$1/trajectory.csv}" i
  for ((i = $1; i <= $2; i++)); do
    cmp -s "$ref" "$tmp/run$i/trajectory.csv" || {
      cmp "$ref" "$tmp/run$i/trajectory.csv" || true
      fail "run $i's trajectory.csv differs from $ref"
    }
  done
}

# refused_runs RUNS PATTERN CONTROLLER...: RUNS runs of a node whose shape lockstep cannot drive:
# every one must end with exit 4 and the plant's message matching PATTERN (grep -E), never exit 0
# (which would be a trajectory that depends on timing), and no run may fly past the first second.
# (The node's output is not checked: a reply it sends after the plant stopped times out.)
refused_runs() {
  local runs="$1" pattern="$2" i rc
  shift 2
  for ((i = 1; i <= runs; i++)); do
    fly "$i" "$@"
    rc=$(cat "$tmp/run$i/rc")
    [ "$rc" = 4 ] || { cat "$tmp/run$i/plant.out"; fail "run $i: plant exited with $rc, expected 4 (refused)"; }
    grep -qE "$pattern" "$tmp/run$i/plant.out" ||
      { cat "$tmp/run$i/plant.out"; fail "run $i: exit 4 without the message /$pattern/"; }
    # Refused at the first control periods: t of the last recorded tick (column 1) below 1 s.
    tail -1 "$tmp/run$i/trajectory.csv" | awk -F, '{ exit !($1 + 0 < 1.0) }' ||
      fail "run $i: refused only at t = $(tail -1 "$tmp/run$i/trajectory.csv" | cut -d, -f1) s"
  done
  grep -hoE "$pattern" "$tmp"/run*/plant.out | sort | uniq -c
}

# flown_or_refused RUNS REFERENCE CONTROLLER...: RUNS runs of a node that labels its commands with
# the oldest stamp of the samples its step used, on an executor that may step it on older samples:
# each run is either flown (check_flown, and REFERENCE's trajectory.csv bytes) or refused with exit 4
# at the very step the node's own log shows on older samples, with that step's oldest stamp as the
# label the plant names. Prints how many of each.
flown_or_refused() {
  local runs="$1" ref="$2" i rc flown=0 refused=0
  shift 2
  for ((i = 1; i <= runs; i++)); do
    fly "$i" "$@"
    rc=$(cat "$tmp/run$i/rc")
    if [ "$rc" = 0 ]; then
      check_flown "$i"
      same_bytes "$i" "$i" "$ref"
      flown=$((flown + 1))
      continue
    fi
    [ "$rc" = 4 ] || { cat "$tmp/run$i/plant.out"; fail "run $i: plant exited with $rc, expected 0 or 4"; }
    local msg tick label
    msg=$(grep -oE "stepped at tick [0-9]+ \(t = [0-9.e+-]+ s\) on samples of t = [0-9.e+-]+ s \(its command's label rotors@[0-9]+\)" \
      "$tmp/run$i/plant.out") || { cat "$tmp/run$i/plant.out"; fail "run $i: exit 4 without naming the step on older samples"; }
    tick=$(sed -E 's/stepped at tick ([0-9]+).*/\1/' <<< "$msg")
    label=$(sed -E 's/.*rotors@([0-9]+).*/\1/' <<< "$msg")
    # The node's first step on older samples is the plant's tick (10 ms plant period), with that label.
    awk -v run="$i" -v t_ns="$((tick * 10000000))" -v label="$label" '
      $1 != $2 || $1 != $3 || $1 != $4 {
        m = $2; if ($3 < m) m = $3; if ($4 < m) m = $4
        if ($1 != t_ns || m != label) { printf "run %s: the node first stepped on older samples at %s ns (oldest %s), the plant named %s ns (%s)\n", run, $1, m, t_ns, label; exit 1 }
        found = 1; exit 0 }
      END { if (!found) { printf "run %s: the plant refused, but no step of the node used older samples\n", run; exit 1 } }' \
      "$tmp/run$i/steps.log" || fail "run $i: the refusal does not name the node's own step on older samples"
    refused=$((refused + 1))
  done
  echo "$flown runs flown (every step on its own samples, the same bytes), $refused refused at the step on older samples"
}

case "$case_arg" in
  rclcpp_lockstep)
    build_rclcpp_controller
    for i in $(seq 1 20); do lockstep_run "$i" "$CTL_CPP"; done
    same_bytes 1 20
    cp "$tmp/run1/trajectory.csv" "$WORK/rclcpp_trajectory.csv"
    echo "20 runs with the rclcpp controller: byte-identical trajectory.csv, every step on its own tick's samples"
    ;;
  rclcpp_no_clock_thread)
    # /clock in the node's own executor (NodeOptions::use_clock_thread(false)): the same bytes.
    build_rclcpp_controller
    for i in 1 2 3; do lockstep_run "$i" "$CTL_CPP" --no-clock-thread; done
    same_bytes 1 3
    lockstep_run 4 "$CTL_CPP"
    same_bytes 1 4
    echo "use_clock_thread false and true: the same bytes"
    ;;
  rclpy_lockstep)
    build_rclcpp_controller
    for i in 1 2 3 4 5; do lockstep_run "$i" "$ROS_PY" "$CTL_PY"; done
    same_bytes 1 5
    lockstep_run 6 "$CTL_CPP"
    same_bytes 1 6
    echo "5 runs with the rclpy controller: byte-identical, and the same bytes as the rclcpp controller"
    ;;
  # Node shapes (docs/ros2.md, "Lockstep with your own ROS 2 controller"): each run either refused
  # (exit 4, the message naming the shape) or flown with every step on its own tick's samples and
  # byte-identical bytes; never exit 0 with a trajectory that depends on timing. Refused runs stop
  # in the first control periods (about 2 s each, the node's start), so 20 of them; flown rclpy runs
  # take about 4 s each, so 20 too.
  rclpy_pose_callback)
    # Publishing from the Pose subscription callback: its command comes before the control tick's
    # /clock.
    refused_runs 20 "sent a command before tick [0-9]+'s /clock .* went out: .* from a subscription callback" \
      "$ROS_PY" "$CTL_PY" --ros-args -p shape:=pose_callback
    echo "20 runs of an rclpy node publishing from its Pose callback: each refused (exit 4) naming the shape"
    ;;
  rclpy_timer_100hz)
    # A timer at 100 Hz, twice the scenario's 50 Hz control rate: two commands per control period.
    refused_runs 20 "(sent a command before tick [0-9]+'s /clock|sent 2 commands in the control period).* from a timer faster than (the control rate|that rate)" \
      "$ROS_PY" "$CTL_PY" --ros-args -p rate_hz:=100.0
    echo "20 runs of an rclpy node with a 100 Hz timer: each refused (exit 4) naming the shape"
    ;;
  rclpy_multithreaded)
    # A 50 Hz timer spun by a MultiThreadedExecutor with 2 threads (the default, mutually exclusive,
    # callback group), its commands labelled with the oldest stamp its step used: a reply can overtake
    # a sensor callback here too (docs/ros2.md; unlabelled, measured once in 56 runs, flown unseen).
    # Each run flown with the single-threaded node's bytes or refused at the step on older samples.
    build_rclcpp_controller
    lockstep_run 21 "$CTL_CPP"
    flown_or_refused 20 "$tmp/run21/trajectory.csv" "$ROS_PY" "$CTL_PY" --ros-args -p executor_threads:=2 -p label:=true
    echo "20 runs of a labelling rclpy node on a 2-thread MultiThreadedExecutor: each flown with the single-threaded bytes or refused at its step on older samples"
    ;;
  rclcpp_multithreaded)
    # rclcpp's MultiThreadedExecutor lets the get_parameters reply overtake a sensor callback (docs/ros2.md;
    # unlabelled, measured: 20 of 20 runs exit 0, each with 2-10 of its 750 steps on the previous tick's
    # Pose or Velocity). Labelled, each run is flown with the single-threaded bytes or refused at the
    # node's first step on older samples.
    build_rclcpp_controller
    lockstep_run 21 "$CTL_CPP"
    flown_or_refused 20 "$tmp/run21/trajectory.csv" "$CTL_CPP" --ros-args -p executor_threads:=2 -p label:=true
    echo "20 runs of a labelling rclcpp node on a 2-thread MultiThreadedExecutor: each flown with the single-threaded bytes or refused at its step on older samples"
    ;;
  rclcpp_labelled)
    # A labelling node on rclcpp::spin: labels change nothing of the flight (the unlabelled node's bytes).
    build_rclcpp_controller
    lockstep_run 4 "$CTL_CPP"
    for i in 1 2 3; do lockstep_run "$i" "$CTL_CPP" --ros-args -p label:=true; done
    same_bytes 1 4
    echo "3 runs of a labelling rclcpp node: the unlabelled node's bytes"
    ;;
  rclpy_slow_steps)
    # A 50 Hz timer whose every 25th step takes 80 ms before it publishes, longer than the plant's
    # 50 ms before it publishes the tick again: the repeat must not hold the /clock that already went
    # out, or the command on its way would be taken for one before the /clock (exit 4). 3 runs (about
    # 6 s each): the same bytes as each other and as the rclcpp node's, every step on its own samples.
    build_rclcpp_controller
    for i in 1 2 3; do lockstep_run "$i" "$ROS_PY" "$CTL_PY" --ros-args -p slow_step_ms:=80; done
    same_bytes 1 3
    lockstep_run 4 "$CTL_CPP"
    same_bytes 1 4
    echo "3 runs of an rclpy node with slow steps (80 ms, past the plant's repeat): the same bytes as the rclcpp node"
    ;;
  rclcpp_pose_callback)
    build_rclcpp_controller
    refused_runs 20 "sent a command before tick [0-9]+'s /clock .* went out: .* from a subscription callback" \
      "$CTL_CPP" --ros-args -p shape:=pose_callback
    echo "20 runs of an rclcpp node publishing from its Pose callback: each refused (exit 4) naming the shape"
    ;;
  cli)
    # A real-time run: ros2 sees quadcosim's nodes and topics, the type hash is valid, and a
    # parameter set from the command line mid-run moves the vehicle.
    build_rclcpp_controller
    "$CTL_CPP" --ros-args -p use_sim_time:=true -p z_des:=1.0 -p log_file:="$tmp/steps.log" > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    "$QC" plant --realtime --scenario "$SCENARIO" --duration 20 --wait-for-controller --timeout 30 \
      --record "$tmp/trajectory.csv" > "$tmp/plant.log" 2>&1 &
    plant=$!
    pids+=("$plant")
    for _ in $(seq 100); do [ -s "$tmp/steps.log" ] && break; sleep 0.1; done
    [ -s "$tmp/steps.log" ] || fail "the controller never stepped"

    # Once the vehicle has settled at z_des = 1 m (t >= 6 s), set z_des = 3 m from the command line.
    for _ in $(seq 300); do
      [ "$(tail -1 "$tmp/steps.log" | cut -d' ' -f1)" -ge 6000000000 ] 2> /dev/null && break
      sleep 0.1
    done
    # The set is made after the controller's newest logged step (simulated time, which runs with the
    # wall clock here): t_set from its own log, not from when this script noticed its first step (a
    # loaded machine notices late, and a wall-clock difference then came out at 5.96 s).
    t_set=$(awk 'NF == 8 { t = $1 } END { print t / 1e9 }' "$tmp/steps.log")  # the last whole line's
    ros2 param set --no-daemon /attitude_controller z_des 3.0 > "$tmp/param.out" 2> "$tmp/param.log" || fail "ros2 param set failed"
    grep -q "Set parameter successful" "$tmp/param.out" || { cat "$tmp/param.out"; fail "ros2 param set was not successful"; }
    ros2 node list --no-daemon --spin-time 3 > "$tmp/node_list.out" 2> "$tmp/node_list.log" || fail "ros2 node list failed"
    for n in /quadrotor_plant /attitude_controller; do
      grep -qx "$n" "$tmp/node_list.out" || { cat "$tmp/node_list.out"; fail "ros2 node list does not show $n"; }
    done

    timeout 20 ros2 topic echo --no-daemon --once /drone/Pose geometry_msgs/msg/PoseStamped > "$tmp/echo.out" 2> "$tmp/echo.log" ||
      fail "ros2 topic echo --once /drone/Pose failed"
    grep -q "frame_id: world" "$tmp/echo.out" || { cat "$tmp/echo.out"; fail "the echoed Pose has no frame_id world"; }

    ros2 topic info -v --no-daemon --spin-time 3 /drone/Pose > "$tmp/info.out" 2> "$tmp/info.log" || fail "ros2 topic info -v failed"
    # The plant's publisher and the controller's subscription, each with the same valid hash.
    grep -q "Node name: quadrotor_plant" "$tmp/info.out" || { cat "$tmp/info.out"; fail "topic info does not show the plant"; }
    hashes=$(sed -n 's/^Topic type hash: //p' "$tmp/info.out" | sort -u)
    [ "$(sed -n 's/^Topic type hash: //p' "$tmp/info.out" | wc -l)" -ge 2 ] || { cat "$tmp/info.out"; fail "fewer than 2 endpoints on /drone/Pose"; }
    [[ "$hashes" =~ ^RIHS01_[0-9a-f]{64}$ ]] || { cat "$tmp/info.out"; fail "the endpoints' type hashes are not one valid RIHS01 hash: $hashes"; }

    rc=0
    wait "$plant" || rc=$?
    [ "$rc" = 0 ] || fail "the plant exited with $rc"
    for f in controller node_list echo info param; do no_warnings "$tmp/$f.log" "$f"; done
    # z near 1 m when the set was started (settled after 6 s), near 3 m at the end (>= 6.5 s after
    # it: within 4 %).
    "$ROS_PY" - "$tmp/trajectory.csv" "$t_set" <<'EOF' || fail "the vehicle did not follow z_des 1 m -> 3 m (above)"
import csv, sys
rows = [r for r in csv.reader(open(sys.argv[1]))][1:]
t_set = float(sys.argv[2])
z = {round(float(r[0]), 2): float(r[3]) for r in rows}
before = z.get(round(t_set - 0.2, 2)) if t_set >= 6.0 else None
end = float(rows[-1][3])
print("param set started at t = %.2f s; z then %s m, z(20 s) = %.3f m" % (t_set, before, end))
ok = 2.88 < end < 3.12 and t_set < 13.5 and before is not None and 0.95 < before < 1.05
sys.exit(0 if ok else 1)
EOF
    echo "ros2 node list, topic echo, topic info -v (hash $hashes) and param set work on quadcosim's nodes"
    ;;
  *)
    echo "unknown case $case_arg" >&2
    exit 2
    ;;
esac
