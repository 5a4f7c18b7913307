#!/usr/bin/env bash
# Benchmark (prints figures; asserts nothing): `quadcosim plant` in lockstep with the rclcpp
# controller of tests/ros2 (a timer on ROS time, rclcpp::spin), the protocol of docs/ros2.md "Lockstep
# with your own ROS 2 controller": the real-time factor of each run, pinned (plant on CPU 0, the
# controller on CPU 1) and unpinned, interleaved.
# Usage: bench/ros2_lockstep.sh [BINARY] [SIMULATED_SECONDS] [RUNS]
# Needs a ROS 2 installation with rclcpp and rmw_cyclonedds_cpp: sourced, or its setup.bash in
# QUADCOSIM_ROS2_SETUP. Builds the controller into build/tests/ros2/work (as the tests do).
set -euo pipefail
cd "$(dirname "$0")/.."
bin="$(realpath "${1:-build/bin/quadcosim}")"
seconds="${2:-60}"
runs="${3:-5}"
if [ -n "${QUADCOSIM_ROS2_SETUP:-}" ]; then
  set +u
  # shellcheck disable=SC1090
  source "$QUADCOSIM_ROS2_SETUP"
  set -u
fi
command -v ros2 > /dev/null || { echo "ros2_lockstep: no ROS 2 installation (source one or set QUADCOSIM_ROS2_SETUP)" >&2; exit 1; }
export RMW_IMPLEMENTATION=rmw_cyclonedds_cpp ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-198}" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
work="build/tests/ros2/work/rclcpp_controller"
cmake -S tests/ros2/rclcpp_controller -B "$work" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work" -j2 > /dev/null
tmp="$(mktemp -d)"
ctl=""
trap '[ -n "$ctl" ] && kill "$ctl" 2> /dev/null; rm -rf "$tmp"' EXIT
one_run() {  # one_run LABEL CONTROLLER_PREFIX PLANT_FLAGS...
  local label="$1" prefix="$2"
  shift 2
  $prefix "$work/attitude_controller" --ros-args -p use_sim_time:=true > "$tmp/controller.log" 2>&1 &
  ctl=$!
  "$bin" plant --scenario scenarios/paper/altitude_step.yaml --schedule-via /attitude_controller \
    --duration "$seconds" --stats "$tmp/stats.json" "$@" > "$tmp/plant.log" 2>&1 || { cat "$tmp/plant.log" >&2; exit 1; }
  kill "$ctl" 2> /dev/null; wait "$ctl" 2> /dev/null || true
  ctl=""
  python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print("%-9s %7.1fx real time  round trip p50 %.0f us" % (sys.argv[2], s["real_time_factor"], s["roundtrip_us_p50"]))' \
    "$tmp/stats.json" "$label"
}
for ((i = 0; i < runs; i++)); do
  one_run pinned "taskset -c 1" --cpus 0
  one_run unpinned ""
done
