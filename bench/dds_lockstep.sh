#!/usr/bin/env bash
# Benchmark (prints figures; asserts nothing): lockstep over DDS, plant and controller as two
# processes on this machine. Prints the real-time factor and the command round trip (sensor
# publication -> motor command back) as JSON, next to Cyclone's own ddsperf ping/pong round trip.
# Usage: bench/dds_lockstep.sh [BINARY] [SIMULATED_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/bin/quadcosim}"
seconds="${2:-600}"
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-199}" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
tmp="$(mktemp -d)"
pids=()
trap 'for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done; rm -rf "$tmp"' EXIT

"$bin" controller --scenario scenarios/paper/altitude_step.yaml > "$tmp/c.log" 2>&1 &
pids+=($!)
"$bin" plant --scenario scenarios/paper/altitude_step.yaml --duration "$seconds" > "$tmp/p.log" 2>&1
rtf=$(sed -n 's/.*(\([0-9.]*\)x real time).*/\1/p' "$tmp/p.log")
p50=$(sed -n 's/.*p50 \([0-9.]*\) us.*/\1/p' "$tmp/p.log")
p99=$(sed -n 's/.*p99 \([0-9.]*\) us.*/\1/p' "$tmp/p.log")

ddsperf_rtt="null"
if command -v ddsperf > /dev/null; then
  # Cyclone's own ping/pong between two processes, for the floor of the middleware.
  timeout 20 ddsperf -D 5 -i "$ROS_DOMAIN_ID" pong > "$tmp/pong.log" 2>&1 &
  pids+=($!)
  timeout 20 ddsperf -D 5 -i "$ROS_DOMAIN_ID" ping > "$tmp/ping.log" 2>&1 || true
  # ddsperf prints lines like "... mean 25.1us min ... 50% 24.3us 90% ... 99% ..."
  ddsperf_rtt=$(sed -n 's/.* 50% \([0-9.]*\)us.*/\1/p' "$tmp/ping.log" | tail -1)
  [ -n "$ddsperf_rtt" ] || ddsperf_rtt="null"
fi
cat <<JSON
{"simulated_s": $seconds, "dds_lockstep_rtf": ${rtf:-null}, "dds_cmd_roundtrip_us_p50": ${p50:-null},
 "dds_cmd_roundtrip_us_p99": ${p99:-null}, "ddsperf_pingpong_rtt_us_p50": $ddsperf_rtt,
 "machine": "$(nproc) cores, $(uname -m), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"}
JSON
