#!/usr/bin/env bash
# Installs what is missing, builds, and runs the paper's four experiments (altitude, roll, pitch, yaw
# steps) as the paper does: plant and controller as two ROS 2 nodes exchanging messages over DDS (in
# lockstep, so the numbers are exactly those of an in-process run). Writes results/<experiment>/ (trajectory.csv, metrics.json, metrics.txt, PNG plots) and
# results/paper_comparison.md (our step figures beside the paper's). Each run is judged against the
# scenario's paper bands (--judge paper: the paper's controller's measured response); exit status 1 if
# any experiment misses one.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh quadcosim > build.log 2>&1 || { tail -50 build.log; echo "build failed (see build.log)"; exit 2; }

# This machine only, unless the caller chose otherwise; the domain is the caller's ROS_DOMAIN_ID (0).
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
mkdir -p results
status=0
dirs=()
for experiment in altitude_step roll_step pitch_step yaw_step; do
  echo "=== ${experiment}"
  # --force: a second reproduction replaces the first one's outputs (exactly the files it wrote).
  ./build/bin/quadcosim run "scenarios/paper/${experiment}.yaml" --out "results/${experiment}" \
    --transport dds --judge paper --force || status=1
  dirs+=("results/${experiment}")
done
echo "=== our step figures beside the paper's (results/paper_comparison.md)"
./build/bin/quadcosim summary "${dirs[@]}" --out results/paper_comparison.md || status=1
exit $status
