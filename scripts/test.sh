#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite: the sanitizer stage (unit tests
# under ASan + UBSan and a bounded run of every fuzz target, scripts/sanitize.sh; skip it with
# QUADCOSIM_SANITIZERS=0), then unit, cross-check, closed-loop, CLI, DDS and plotting tests through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
if [ "${QUADCOSIM_SANITIZERS:-1}" != 0 ]; then
  ./scripts/sanitize.sh
fi
ctest --test-dir build --output-on-failure -j"${QUADCOSIM_JOBS:-2}" --timeout 600
