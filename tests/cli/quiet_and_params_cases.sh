#!/usr/bin/env bash
# Correct runs say nothing alarming, and `params` lists a Python class's parameters.
# Usage: quiet_and_params_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# Cases: quiet_runs (altitude_step in-process and over DDS, with the paper controller and with a
# class written in Python (tests/newcomer/cascade.py): no "not answered" and no warning on stderr;
# the Python class over DDS three times, as a tick went unanswered in about one run in two when the
# controller's thread was freed after its answer had gone out), params_python (`params --controller
# python:MODULE:CLASS` lists the class's declared parameters with their units, ranges and defaults
# as cascade.py declares them, after the node's). Cases needing Python exit 77 on a CLI built without.
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
export PYTHONPATH="$src/tests/newcomer${PYTHONPATH:+:$PYTHONPATH}"
alt="$src/scenarios/paper/altitude_step.yaml"

# quiet NAME ARGS...: runs `quadcosim run ARGS`, which must exit 0 with no alarm on stderr.
quiet() {
  local name="$1" rc
  shift
  set +e
  timeout 120 "$bin" run "$@" --out "$tmp/$name" --no-plots > "$tmp/$name.out" 2> "$tmp/$name.log"
  rc=$?
  set -e
  [ "$rc" -eq 0 ] || fail "$name: exit $rc"
  if grep -inE "not answered|warning|late periods" "$tmp/$name.log"; then fail "$name: an alarm on stderr"; fi
  echo "ok: $name"
}

case "$case_name" in
  quiet_runs)
    quiet inprocess "$alt"
    quiet dds "$alt" --transport dds
    skip_without_python "$bin"
    quiet inprocess_python "$alt" --controller python:cascade:Cascade
    for i in 1 2 3; do quiet "dds_python_$i" "$alt" --controller python:cascade:Cascade --transport dds; done
    ;;
  params_python)
    skip_without_python "$bin"
    "$bin" params --controller python:cascade:Cascade > "$tmp/params.txt" 2> "$tmp/params.log" ||
      fail "params --controller python:cascade:Cascade: exit $?"
    # The node's parameters first, then the class's as cascade.py declares them (name, unit, range,
    # default), then step_timeout_s, which every Python controller has.
    grep -qE '^z_des[[:space:]]' "$tmp/params.txt" || fail "the node's z_des is not listed: $(cat "$tmp/params.txt")"
    for row in 'kp_xy +1/s\^2 +\[0, 100\] +1\.44 ' 'kd_z +1/s +\[0, 100\] +3\.2 ' 'k_rate +1/s +\[0, 200\] +18 ' \
               'max_tilt +rad +\[0\.05, 1\.2\] +0\.6 ' 'step_timeout_s +s '; do
      grep -qE "^$row" "$tmp/params.txt" || fail "no row /$row/ in: $(cat "$tmp/params.txt")"
    done
    [ "$(grep -cE '^(kp_xy|kd_xy|kp_z|kd_z|k_att|k_att_yaw|k_rate|k_rate_yaw|max_tilt) ' "$tmp/params.txt")" -eq 9 ] ||
      fail "expected cascade.py's nine parameters: $(cat "$tmp/params.txt")"
    # A class that is not there: an error naming it, exit 2.
    set +e
    "$bin" params --controller python:cascade:NoSuchClass > /dev/null 2> "$tmp/missing.log"
    rc=$?
    set -e
    [ "$rc" -eq 2 ] || fail "params with a missing class: exit $rc, expected 2"
    grep -q "NoSuchClass" "$tmp/missing.log" || fail "the error does not name the class: $(cat "$tmp/missing.log")"
    echo "ok: params lists cascade.py's parameters"
    ;;
  *) fail "unknown case" ;;
esac
