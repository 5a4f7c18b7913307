#!/usr/bin/env bash
# Runs every libFuzzer target for a bounded time on its committed corpus (which replays every seed
# and every regression input first), without changing the corpus. Exits 1 on the first crash, leak,
# sanitizer report, timeout or failed check, and prints the reproducer.
#   usage: run_fuzz.sh FUZZ_BIN_DIR SOURCE_DIR [SECONDS_PER_TARGET]   (default: $QUADCOSIM_FUZZ_SECONDS or 20)
set -euo pipefail
bin="$1"; src="$2"; seconds="${3:-${QUADCOSIM_FUZZ_SECONDS:-20}}"
artifacts="$bin/artifacts"
mkdir -p "$artifacts"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# fuzz_messages and fuzz_parameters open a DDS participant without discovery; a domain id of the
# test range all the same.
export ROS_DOMAIN_ID=$((165 + ${QUADCOSIM_TEST_DOMAIN_OFFSET:-0})) ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1}" UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"

for target in fuzz_config fuzz_messages fuzz_parameters fuzz_model_description; do
  corpus="$src/tests/fuzz/corpus/$target"
  mkdir -p "$work/$target"
  dict=()
  [ -f "$src/tests/fuzz/$target.dict" ] && dict=(-dict="$src/tests/fuzz/$target.dict")
  log="$work/$target.log"
  set +e
  "$bin/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=3072 -print_final_stats=1 \
    -artifact_prefix="$artifacts/$target-" "${dict[@]}" "$work/$target" "$corpus" > "$log" 2>&1
  rc=$?
  set -e
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  if [ "$rc" -ne 0 ]; then
    tail -60 "$log"
    echo "FAIL $target (exit $rc): reproducer(s) in $artifacts:"
    ls -1 "$artifacts" | grep "^$target-" || true
    echo "replay one with: $bin/$target FILE; once fixed, add it to $corpus as regression_<what>"
    exit 1
  fi
  echo "fuzz $target: ${runs:-?} inputs in ${seconds} s (corpus $(ls "$corpus" | wc -l) files), no failure"
done
