#!/usr/bin/env bash
# The sanitizer stage of the test suite (docs/reliability.md): builds the unit tests and the fuzz
# targets with clang, AddressSanitizer and UndefinedBehaviorSanitizer (any report aborts) into
# build-asan/, runs the unit tests there, then every fuzz target for QUADCOSIM_FUZZ_SECONDS (default
# 20) seconds on its committed corpus. Exits non-zero on the first failure.
#   QUADCOSIM_FUZZ_SECONDS=0 builds and runs the unit tests only. Without the precompiled header
# (QUADCOSIM_PCH): its build is for finding faults, not for speed.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${QUADCOSIM_JOBS:-2}"
seconds="${QUADCOSIM_FUZZ_SECONDS:-20}"
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"  # hits across clones of the repository
fi
# -O1: sanitizer reports keep usable stacks, the tests stay quick.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DQUADCOSIM_FUZZ=ON \
  -DQUADCOSIM_TEST_DOMAIN_OFFSET="${QUADCOSIM_TEST_DOMAIN_OFFSET:-0}" -DQUADCOSIM_PCH=OFF "${launcher[@]}" > /dev/null
unit_tests=(util_test model_test control_test analysis_test sim_test io_test security_test fmi_test worker_pool_test isolation_test)
targets=()
for t in "${unit_tests[@]}" fuzz_config fuzz_messages fuzz_parameters fuzz_model_description; do targets+=(--target "$t"); done
cmake --build build-asan -j"$jobs" "${targets[@]}"

export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}" UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
for t in "${unit_tests[@]}"; do
  echo "sanitize: $t (ASan + UBSan)"
  build-asan/tests/"$t" --gtest_brief=1
done
if [ "$seconds" != 0 ]; then
  bash tests/fuzz/run_fuzz.sh build-asan/fuzz . "$seconds"
fi
