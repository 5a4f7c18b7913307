#!/usr/bin/env bash
# Benchmark (prints figures; asserts nothing): lockstep over DDS, plant and controller as two
# processes on this machine: the real-time factor and the command round trip (sensor publication ->
# motor command back) as JSON, next to Cyclone's own ddsperf ping/pong round trip. The same
# measurement as the "dds" part of `quadcosim bench` (docs/performance.md), which this runs.
# Usage: bench/dds_lockstep.sh [BINARY] [SIMULATED_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/bin/quadcosim}"
seconds="${2:-600}"
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-199}" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
exec "$bin" bench --json --only dds --seconds "$seconds"
