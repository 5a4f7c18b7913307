#!/usr/bin/env bash
# Configures and builds quadcosim (Release) into build/; the binary is build/bin/quadcosim.
# Usage: scripts/build.sh [TARGET...]   (default: everything, tests included)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${QUADCOSIM_JOBS:-2}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j"$jobs" "${targets[@]}"
