#!/usr/bin/env bash
# Benchmark (prints figures; asserts nothing): what DDS Security costs in lockstep. Runs the altitude
# scenario with plant and controller as two processes, first unsecured, then secured (a fresh
# keystore, default governance: discovery and data encrypted, RTPS signed), and prints JSON: real-time
# factor and command round trip p50/p99 of each, and the wall time of each whole run (start-up,
# including the security handshakes, to exit).
# Usage: bench/dds_lockstep_security.sh [BINARY] [SIMULATED_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/bin/quadcosim}"
seconds="${2:-300}"
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-198}" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_SECURITY_ENABLE ROS_SECURITY_STRATEGY ROS_SECURITY_KEYSTORE ROS_SECURITY_ENCLAVE_OVERRIDE
tmp="$(mktemp -d)"
pids=()
trap 'for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done; rm -rf "$tmp"' EXIT
scenario=scenarios/paper/altitude_step.yaml

# pair NAME [ENCLAVE_PREFIX]: one lockstep run; prints a JSON object of its figures.
pair() {
  local name="$1" plant_args=() controller_args=()
  if [ -n "${2:-}" ]; then plant_args=(--enclave "$2/plant"); controller_args=(--enclave "$2/controller"); fi
  local start end
  start=$(date +%s.%N)
  "$bin" controller --scenario "$scenario" "${controller_args[@]}" > "$tmp/$name.c.log" 2>&1 &
  local cpid=$!
  pids+=("$cpid")
  "$bin" plant --scenario "$scenario" --duration "$seconds" "${plant_args[@]}" > "$tmp/$name.p.log" 2>&1
  end=$(date +%s.%N)
  kill "$cpid" 2>/dev/null || true
  wait "$cpid" 2>/dev/null || true
  local rtf p50 p99
  rtf=$(sed -n 's/.*(\([0-9.]*\)x real time).*/\1/p' "$tmp/$name.p.log")
  p50=$(sed -n 's/.*p50 \([0-9.]*\) us.*/\1/p' "$tmp/$name.p.log")
  p99=$(sed -n 's/.*p99 \([0-9.]*\) us.*/\1/p' "$tmp/$name.p.log")
  printf '"%s": {"rtf": %s, "cmd_roundtrip_us_p50": %s, "cmd_roundtrip_us_p99": %s, "wall_s": %.3f}' \
    "$name" "${rtf:-null}" "${p50:-null}" "${p99:-null}" "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')"
}

unsecured=$(pair unsecured)
"$bin" security create-keystore "$tmp/ks" > /dev/null
for e in plant controller; do "$bin" security create-enclave "$tmp/ks" "/bench/$e" > /dev/null; done
export ROS_SECURITY_ENABLE=true ROS_SECURITY_STRATEGY=Enforce ROS_SECURITY_KEYSTORE="$tmp/ks"
secured=$(pair secured /bench)
cat <<JSON
{"simulated_s": $seconds, $unsecured,
 $secured,
 "machine": "$(nproc) cores, $(uname -m), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"}
JSON
