#!/usr/bin/env bash
# `quadcosim plant` and `quadcosim controller` refuse a flag that would do nothing in the mode chosen
# (lockstep or --realtime, one vehicle or --vehicles N): exit 2, naming the flag and the mode. The
# combinations each mode takes still parse: they reach the command, which then stops at a bad
# vehicle file with that file's own error. No case reaches the network (flags and files come first).
#   usage: node_flags_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE   (CASE: plant or controller)
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
export ROS_DOMAIN_ID=$((166 + ${QUADCOSIM_TEST_DOMAIN_OFFSET:-0})) ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
cd "$TMP"
printf 'mass_kg: 1.0\nlayout: h\n' > bad.yaml
BAD_VEHICLE="bad.yaml: layout: got 'h', expected one of 'plus' 'x'"

# refused "MESSAGE" ARGS...: exit 2 and MESSAGE on stderr.
refused() {
  local want=$1
  shift
  set +e
  timeout 20 "$QC" "$@" > out.log 2> err.log
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || { cat out.log err.log >&2; fail "'$*' exited $rc, expected 2"; }
  grep -qF -- "$want" err.log || { cat err.log >&2; fail "'$*' did not say: $want"; }
}
# accepted ARGS...: the flags parse (no "does nothing"), and the command stops at bad.yaml.
accepted() {
  refused "$BAD_VEHICLE" "$@" --vehicle bad.yaml
  if grep -q "does nothing" err.log; then cat err.log >&2; fail "'$*' refused a flag that acts"; fi
}

case "$CASE" in
  plant)
    refused "--rate-factor: does nothing with lockstep; it needs --realtime" plant --rate-factor 2
    refused "--wait-for-controller: does nothing with lockstep" plant --wait-for-controller
    refused "--on-timeout: does nothing with --realtime" plant --realtime --on-timeout hold
    refused "--timeout: does nothing with --realtime alone" plant --realtime --timeout 3
    refused "--realtime: does nothing with --vehicles; a swarm runs in lockstep only" plant --vehicles 4 --realtime
    refused "--record: does nothing with --vehicles" plant --vehicles 4 --record t.csv
    refused "--namespace: does nothing with --vehicles" plant --vehicles 4 --namespace /a
    refused "--schedule-via: does nothing with --vehicles" plant --vehicles 4 --schedule-via /attitude_controller
    refused "--swarm-out: does nothing with one vehicle; it needs --vehicles N" plant --swarm-out sw
    refused "--threads: does nothing with one vehicle" plant --threads 2
    accepted plant --on-timeout hold --timeout 3 --namespace /a --record t.csv --mcap t.mcap \
      --schedule-via /attitude_controller --watchdog 0.5 --watchdog-policy hold --stats s.json
    accepted plant --realtime --rate-factor 2 --wait-for-controller --timeout 3 --record t.csv --watchdog 0.3
    accepted plant --realtime --schedule-via /attitude_controller --timeout 3
    accepted plant --vehicles 4 --ns-prefix /s --threads 2 --swarm-out sw --on-timeout hold --timeout 3 \
      --stats s.json --sensor-qos --watchdog-policy stop
    [ ! -e t.csv ] && [ ! -e sw ] || fail "a refused or stopped plant wrote an output"
    ;;
  controller)
    refused "--stats: does nothing with lockstep; it needs --realtime" controller --stats s.json
    refused "--rt-priority: does nothing with lockstep" controller --rt-priority 10
    refused "--rate-factor: does nothing with lockstep" controller --rate-factor 2
    refused "--realtime: does nothing with --vehicles; a swarm runs in lockstep only" controller --vehicles 3 --realtime
    refused "--node-name: does nothing with --vehicles" controller --vehicles 3 --node-name ctl
    refused "--namespace: does nothing with --vehicles" controller --vehicles 3 --namespace /a
    refused "--ns-prefix: does nothing with one vehicle; it needs --vehicles N" controller --ns-prefix /s
    accepted controller --realtime --rate-factor 2 --rt-priority 10 --stats s.json --node-name ctl --namespace /a
    accepted controller --no-schedule --node-name ctl --sensor-qos
    accepted controller --vehicles 3 --ns-prefix /s --threads 2 --no-schedule
    [ ! -e s.json ] || fail "a refused or stopped controller wrote --stats"
    ;;
  *)
    fail "unknown case"
    ;;
esac
echo "PASS [$CASE]"
