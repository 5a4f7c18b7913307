#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (unit, cross-check, closed-loop,
# CLI and plotting tests) through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
ctest --test-dir build --output-on-failure -j"${QUADCOSIM_JOBS:-2}" --timeout 600
