#!/usr/bin/env bash
# Configures and builds quadcosim (Release) into build/; the binary is build/bin/quadcosim.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${QUADCOSIM_JOBS:-2}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j"$jobs"
