# Sourced by the tests that start real processes: `source process_case.sh CASE_NAME DOMAIN_ID`.
# Puts the case on its own ROS_DOMAIN_ID with localhost-only discovery (and no inherited discovery
# or security settings), makes $tmp, and ends every process the case started, also on failure:
# those listed in the array `pids` and any background job of the script. `fail MESSAGE` prints the
# case name, the message and the tail of every $tmp/*.log, and exits 1.
set -euo pipefail
case_name="$1"
export ROS_DOMAIN_ID="$2" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
unset ROS_SECURITY_ENABLE ROS_SECURITY_STRATEGY ROS_SECURITY_KEYSTORE ROS_SECURITY_ENCLAVE_OVERRIDE
tmp="$(mktemp -d)"
pids=()
cleanup() {
  # A job that runs a shell function (`secure ... &`) is a subshell whose command is its child: end the
  # children first, or they outlive the case (two real-time controllers were found running minutes later).
  for p in "${pids[@]}" $(jobs -p); do
    pkill -KILL -P "$p" 2>/dev/null || true
    kill -KILL "$p" 2>/dev/null || true
  done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL [$case_name]: $*"
  for f in "$tmp"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -20 "$f"; }; done
  exit 1
}

# skip_without_python BINARY: exits 77 (SKIPPED), saying why, when that quadcosim was built without
# Python controllers.
skip_without_python() {
  if "$1" controller --python "no_such_module_for_the_check:X" > "$tmp/check.log" 2>&1; then :; fi
  if grep -q "built without Python" "$tmp/check.log"; then
    echo "SKIP: this quadcosim was built without Python: $(cat "$tmp/check.log")"
    exit 77
  fi
  rm -f "$tmp/check.log"
}
