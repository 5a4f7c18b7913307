#!/usr/bin/env bash
# DDS Security with real processes. Usage: security_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# Every case runs on its own ROS_DOMAIN_ID with localhost-only discovery, makes its own keystore in a
# temporary directory, and ends every process it started (trap), also on failure.
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
scenario="$src/scenarios/paper/altitude_step.yaml"
# shellcheck source=../lib/same_recording.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/same_recording.sh"
ks="$tmp/keystore"

# Secured settings for one command: secure ENCLAVE COMMAND...
secure() {
  local enclave="$1"; shift
  ROS_SECURITY_ENABLE=true ROS_SECURITY_STRATEGY=Enforce ROS_SECURITY_KEYSTORE="$ks" "$@" --enclave "$enclave"
}

# The largest altitude z [m] in a trajectory CSV (column 4).
max_z() { awk -F, 'NR > 1 && $4 > m { m = $4 } END { printf "%.6f\n", m + 0 }' "$1"; }

# A secured real-time plant recording to $tmp/plant.csv for $1 simulated seconds, in the background.
start_secured_plant() {
  secure /quadcosim/plant "$bin" plant --scenario "$scenario" --realtime --duration "$1" \
    --record "$tmp/plant.csv" > "$tmp/plant.log" 2>&1 &
  pids+=($!)
  plant_pid=$!
}

# Waits for the plant started above; it must end on its own with exit 0.
finish_plant() {
  wait "$plant_pid" || fail "the secured plant failed"
  grep -q "security (Enforce): enclave /quadcosim/plant" "$tmp/plant.log" || fail "the plant did not run secured"
}

case "$case_name" in
  secured_identical)  # run --keystore: secured end to end, the same bytes as in-process
    "$bin" run "$scenario" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process run failed"
    "$bin" run "$scenario" --out "$tmp/sec" --no-plots --transport dds --keystore "$ks" > "$tmp/sec.log" 2>&1 \
      || fail "secured DDS run failed"
    for who in plant controller; do
      grep -q "security (Enforce): enclave /quadcosim/$who from $ks/enclaves/quadcosim/$who" "$tmp/sec.log" \
        || fail "the $who did not run secured"
      [ -f "$ks/enclaves/quadcosim/$who/permissions.p7s" ] || fail "enclave /quadcosim/$who not created"
    done
    cmp "$tmp/in/trajectory.csv" "$tmp/sec/trajectory.csv" || fail "trajectories differ"
    /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/../lib/same_metrics.py" "$tmp/in/metrics.json" "$tmp/sec/metrics.json" || fail "metrics differ"
    same_recording "$tmp/in/run.mcap" "$tmp/sec/run.mcap" || fail "MCAP recordings differ"
    [ "$(wc -l < "$tmp/sec/trajectory.csv")" -gt 500 ] || fail "trajectory too short"
    # A second run uses the keystore as it is (nothing re-created).
    "$bin" run "$scenario" --out "$tmp/sec2" --no-plots --transport dds --keystore "$ks" > "$tmp/sec2.log" 2>&1 \
      || fail "second secured run failed"
    ! grep -q "created" "$tmp/sec2.log" || fail "the second run re-created keystore or enclaves"
    cmp "$tmp/in/trajectory.csv" "$tmp/sec2/trajectory.csv" || fail "second secured trajectory differs"
    ;;

  unauthenticated)  # no credentials: sees no pose, and its motor commands do not reach the plant
    "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1 || fail "create-keystore failed"
    for e in /quadcosim/plant /viewer; do
      "$bin" security create-enclave "$ks" "$e" >> "$tmp/ks.log" 2>&1 || fail "create-enclave $e failed"
    done
    start_secured_plant 4
    # An unsecured controller publishes motor commands at 50 Hz for as long as the plant runs.
    "$bin" controller --scenario "$scenario" --realtime > "$tmp/intruder.log" 2>&1 &
    pids+=($!)
    # An unsecured echo sees only the intruder's own subscription to /drone/Pose: it waits for a
    # message that never comes (killed by timeout, 124), or finds no topic at all (2).
    set +e
    timeout 2 "$bin" topic echo /drone/Pose --count 1 --wait 1.5 > "$tmp/echo_unsecured.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 124 ] || [ "$rc" -eq 2 ] || fail "unsecured topic echo: expected no message, got exit $rc"
    ! grep -q "position:" "$tmp/echo_unsecured.log" || fail "unsecured echo printed a pose"
    # The pose is there for a participant with credentials (so the silence above is security's).
    timeout 20 bash -c "$(declare -f secure); ks='$ks'; secure /viewer '$bin' topic echo /drone/Pose --count 1 --wait 5" \
      > "$tmp/echo_secured.log" 2>&1 || fail "secured topic echo failed"
    grep -q "frame_id: world" "$tmp/echo_secured.log" || fail "secured echo printed no pose"
    finish_plant
    grep -q "commands received 0," "$tmp/plant.log" || fail "the plant accepted commands from an unsecured controller"
    [ "$(max_z "$tmp/plant.csv")" = "0.000000" ] || fail "the vehicle climbed to $(max_z "$tmp/plant.csv") m"
    [ "$(wc -l < "$tmp/plant.csv")" -gt 300 ] || fail "plant trajectory too short"
    ;;

  denied_publish)  # a valid identity without permission to publish motor commands is refused
    "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1 || fail "create-keystore failed"
    "$bin" security create-enclave "$ks" /quadcosim/plant >> "$tmp/ks.log" 2>&1 || fail "create-enclave plant failed"
    "$bin" security create-enclave "$ks" /rogue --deny-publish /drone/motor_commands >> "$tmp/ks.log" 2>&1 \
      || fail "create-enclave --deny-publish failed"
    "$bin" security check "$ks" /rogue > "$tmp/check.log" 2>&1 || fail "the /rogue enclave is not usable"
    start_secured_plant 4
    set +e
    timeout 20 bash -c "$(declare -f secure); ks='$ks'; secure /rogue '$bin' controller --scenario '$scenario' --realtime" \
      > "$tmp/rogue.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "the denied controller ran (exit $rc)"
    grep -q "security (Enforce): enclave /rogue" "$tmp/rogue.log" || fail "the rogue did not authenticate"
    grep -q "drone/motor_commands failed: Not Allowed By Security" "$tmp/rogue.log" \
      || fail "no access-control refusal naming /drone/motor_commands"
    # A participant that skips that local check: its own governance (signed with the CA key, which a
    # real intruder would not have) leaves the command topic unprotected, so it creates its writer;
    # the plant, under the keystore's governance, refuses to match it.
    sed 's|<topic_access_rules>|&<topic_rule><topic_expression>rt/drone/motor_commands</topic_expression><enable_discovery_protection>true</enable_discovery_protection><enable_liveliness_protection>true</enable_liveliness_protection><enable_read_access_control>false</enable_read_access_control><enable_write_access_control>false</enable_write_access_control><metadata_protection_kind>ENCRYPT</metadata_protection_kind><data_protection_kind>ENCRYPT</data_protection_kind></topic_rule>|' \
      "$ks/enclaves/governance.xml" > "$tmp/bypass_governance.xml"
    "$bin" security create-enclave "$ks" /bypass --deny-publish /drone/motor_commands >> "$tmp/ks.log" 2>&1 \
      || fail "create-enclave /bypass failed"
    rm "$ks/enclaves/bypass/governance.p7s"
    openssl smime -sign -text -in "$tmp/bypass_governance.xml" -out "$ks/enclaves/bypass/governance.p7s" \
      -signer "$ks/public/ca.cert.pem" -inkey "$ks/private/ca.key.pem" || fail "cannot sign the bypass governance"
    set +e
    timeout 1.5 bash -c "$(declare -f secure); ks='$ks'; secure /bypass '$bin' controller --scenario '$scenario' --realtime" \
      > "$tmp/bypass.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -eq 124 ] || fail "the bypassing controller did not run until stopped (exit $rc)"
    ! grep -q "Not Allowed By Security" "$tmp/bypass.log" || fail "the bypass was refused locally"
    finish_plant
    grep -q "commands received 0," "$tmp/plant.log" || fail "a denied command reached the plant"
    [ "$(max_z "$tmp/plant.csv")" = "0.000000" ] || fail "the vehicle climbed"
    grep -q "match_remote_writer .* security_attributes mismatch" "$tmp/plant.log" \
      || fail "the plant did not refuse the bypassing writer"
    ;;

  enforce_missing)  # Enforce refuses unusable credentials by name; Permissive warns and runs unsecured
    "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1 || fail "create-keystore failed"
    "$bin" security create-enclave "$ks" /quadcosim/plant >> "$tmp/ks.log" 2>&1 || fail "create-enclave failed"
    rm "$ks/enclaves/quadcosim/plant/key.pem"
    expect_refusal() {  # expect_refusal TEXT COMMAND...: exits non-zero at once, naming TEXT
      local text="$1"; shift
      set +e
      timeout 20 "$@" > "$tmp/refused.log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "expected a refusal, got exit $rc: $*"
      grep -qF -- "$text" "$tmp/refused.log" || fail "the refusal does not name '$text'"
    }
    export ROS_SECURITY_ENABLE=true ROS_SECURITY_STRATEGY=Enforce ROS_SECURITY_KEYSTORE="$ks"
    expect_refusal "$ks/enclaves/quadcosim/plant/key.pem: missing" \
      "$bin" plant --scenario "$scenario" --enclave /quadcosim/plant --timeout 1
    expect_refusal "$ks/enclaves/nobody: no such directory" "$bin" controller --enclave /nobody
    expect_refusal "$ks/enclaves/cert.pem: missing" "$bin" topic list --wait 0.1   # enclave "/"
    ROS_SECURITY_ENCLAVE_OVERRIDE=/nobody expect_refusal "enclave /nobody unusable" "$bin" topic list --wait 0.1
    cp "$ks/enclaves/quadcosim/plant/cert.pem" "$ks/enclaves/quadcosim/plant/key.pem"  # not a key
    expect_refusal "key.pem: not an unencrypted PEM private key" "$bin" topic list --wait 0.1 --enclave /quadcosim/plant
    ROS_SECURITY_KEYSTORE= expect_refusal "ROS_SECURITY_KEYSTORE is not set" "$bin" topic list --wait 0.1
    expect_refusal "must not start with a digit" "$bin" topic list --wait 0.1 --enclave /4x
    # Credentials for another domain: Cyclone refuses the participant and says why.
    "$bin" security create-keystore "$tmp/other" --domain-id 3 > /dev/null 2>&1 || fail "create-keystore 3 failed"
    "$bin" security create-enclave "$tmp/other" /tools --domain-id 3 > /dev/null 2>&1 || fail "create-enclave 3 failed"
    ROS_SECURITY_KEYSTORE="$tmp/other" expect_refusal "Could not find domain $ROS_DOMAIN_ID in governance" \
      "$bin" topic list --wait 0.1 --enclave /tools
    # Permissive: a warning naming the problem, then the command runs without security.
    ROS_SECURITY_STRATEGY=Permissive "$bin" topic list --wait 0.1 --enclave /quadcosim/plant > "$tmp/permissive.log" 2>&1 \
      || fail "Permissive did not run"
    grep -q "security (Permissive): .*key.pem.*running WITHOUT security" "$tmp/permissive.log" \
      || fail "Permissive gave no warning"
    ;;

  foreign_keystore)  # a keystore made with the openssl command line in SROS2's layout serves our nodes
    mkdir -p "$ks/public" "$ks/private" "$ks/enclaves"
    (
      cd "$ks"
      openssl ecparam -name prime256v1 -genkey -noout | openssl pkcs8 -topk8 -nocrypt -out private/ca.key.pem
      openssl req -new -x509 -key private/ca.key.pem -out public/ca.cert.pem -days 3650 -subj "/CN=sros2CA" \
        -addext "basicConstraints=critical,CA:TRUE,pathlen:1"
      for role in identity_ca permissions_ca; do
        ln -s ca.cert.pem "public/$role.cert.pem"; ln -s ca.key.pem "private/$role.key.pem"
      done
      # sros2's default governance, written out here independently of quadcosim.
      cat > enclaves/governance.xml <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules><domain_rule>
    <domains><id>$ROS_DOMAIN_ID</id></domains>
    <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
    <enable_join_access_control>true</enable_join_access_control>
    <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
    <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
    <rtps_protection_kind>SIGN</rtps_protection_kind>
    <topic_access_rules><topic_rule>
      <topic_expression>*</topic_expression>
      <enable_discovery_protection>true</enable_discovery_protection>
      <enable_liveliness_protection>true</enable_liveliness_protection>
      <enable_read_access_control>true</enable_read_access_control>
      <enable_write_access_control>true</enable_write_access_control>
      <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
      <data_protection_kind>ENCRYPT</data_protection_kind>
    </topic_rule></topic_access_rules>
  </domain_rule></domain_access_rules>
</dds>
EOF
      openssl smime -sign -text -in enclaves/governance.xml -out enclaves/governance.p7s \
        -signer public/permissions_ca.cert.pem -inkey private/permissions_ca.key.pem
    ) > "$tmp/openssl.log" 2>&1 || fail "openssl could not make the keystore"
    "$bin" run "$scenario" --out "$tmp/sec" --no-plots --transport dds --keystore "$ks" > "$tmp/sec.log" 2>&1 \
      || fail "secured run with the openssl-made keystore failed"
    grep -q "created enclave /quadcosim/plant" "$tmp/sec.log" || fail "enclave not added to the existing keystore"
    ! grep -q "created keystore" "$tmp/sec.log" || fail "the existing keystore was replaced"
    grep -q "security (Enforce): enclave /quadcosim/controller" "$tmp/sec.log" || fail "controller not secured"
    openssl verify -CAfile "$ks/public/ca.cert.pem" "$ks/enclaves/quadcosim/plant/cert.pem" > "$tmp/verify.log" 2>&1 \
      || fail "our identity does not verify against the openssl-made CA"
    ;;

  read_only_monitor)  # --read-only: a monitoring station reads everything and can move nothing
    "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1 || fail "create-keystore failed"
    for e in /quadcosim/plant /quadcosim/controller /tools; do
      "$bin" security create-enclave "$ks" "$e" >> "$tmp/ks.log" 2>&1 || fail "create-enclave $e failed"
    done
    "$bin" security create-enclave "$ks" /monitor --read-only >> "$tmp/ks.log" 2>&1 \
      || fail "create-enclave --read-only failed"
    "$bin" security check "$ks" /monitor > "$tmp/check.log" 2>&1 || fail "the /monitor enclave is not usable"
    start_secured_plant 5
    secure /quadcosim/controller "$bin" controller --scenario "$scenario" --realtime > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    in_monitor() { timeout 20 bash -c "$(declare -f secure); ks='$ks'; secure /monitor $*"; }
    # It reads: the pose and the motor commands.
    in_monitor "'$bin' topic echo /drone/Pose --count 1 --wait 5" > "$tmp/monitor_pose.log" 2>&1 \
      || fail "the monitor cannot read /drone/Pose"
    grep -q "frame_id: world" "$tmp/monitor_pose.log" || fail "the monitor printed no pose"
    in_monitor "'$bin' topic echo /drone/motor_commands --count 1 --wait 5" > "$tmp/monitor_cmd.log" 2>&1 \
      || fail "the monitor cannot read /drone/motor_commands"
    # It writes nothing: a parameter change (the attack: z_des 8.0), motor commands, sensor messages.
    refused_in_monitor() {  # refused_in_monitor LOG COMMAND...: exits non-zero, refused by access control
      local log="$1"; shift
      set +e
      in_monitor "$*" > "$tmp/$log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "the monitor ran '$*' (exit $rc)"
      grep -q "Not Allowed By Security" "$tmp/$log" || fail "'$*' was not refused by access control"
    }
    refused_in_monitor monitor_param.log "'$bin' param set /attitude_controller z_des 8.0"
    grep -q "rq/attitude_controller/set_parametersRequest" "$tmp/monitor_param.log" \
      || fail "the parameter refusal does not name the request topic"
    refused_in_monitor monitor_controller.log "'$bin' controller --scenario '$scenario' --realtime"
    refused_in_monitor monitor_plant.log "'$bin' plant --scenario '$scenario' --realtime --duration 1"
    # The controller's z_des is the scenario's 10 m, not the monitor's 8 m (read with a full enclave).
    timeout 20 bash -c "$(declare -f secure); ks='$ks'; secure /tools '$bin' param get /attitude_controller z_des" \
      > "$tmp/get.log" 2>&1 || fail "param get from /tools failed"
    grep -qx "Double value is: 10.0" "$tmp/get.log" || fail "z_des changed: $(cat "$tmp/get.log")"
    finish_plant
    ;;

  deny_publish_params)  # --deny-publish also denies setting parameters; the topic stays readable
    "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1 || fail "create-keystore failed"
    for e in /quadcosim/plant /quadcosim/controller; do
      "$bin" security create-enclave "$ks" "$e" >> "$tmp/ks.log" 2>&1 || fail "create-enclave $e failed"
    done
    "$bin" security create-enclave "$ks" /station --deny-publish /drone/motor_commands >> "$tmp/ks.log" 2>&1 \
      || fail "create-enclave --deny-publish failed"
    start_secured_plant 5
    secure /quadcosim/controller "$bin" controller --scenario "$scenario" --realtime > "$tmp/controller.log" 2>&1 &
    pids+=($!)
    in_station() { timeout 20 bash -c "$(declare -f secure); ks='$ks'; secure /station $*"; }
    set +e
    in_station "'$bin' param set /attitude_controller z_des 8.0" > "$tmp/station_set.log" 2>&1
    rc=$?
    set -e
    [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "the station set a controller parameter (exit $rc)"
    grep -q "rq/attitude_controller/set_parametersRequest failed: Not Allowed By Security" "$tmp/station_set.log" \
      || fail "the parameter change was not refused by access control"
    # Reading parameters and the denied topic itself stays allowed.
    # z_des is 0 until the scenario's schedule sets 10 m at the start of the run (a read under load can
    # come first); it must become 10 and never be the station's 8.
    for attempt in 1 2 3 4 5 6; do
      in_station "'$bin' param get /attitude_controller z_des" > "$tmp/station_get.log" 2>&1 \
        || fail "the station cannot read a parameter"
      ! grep -qx "Double value is: 8.0" "$tmp/station_get.log" || fail "the station changed z_des"
      grep -qx "Double value is: 10.0" "$tmp/station_get.log" && break
      sleep 0.5
    done
    grep -qx "Double value is: 10.0" "$tmp/station_get.log" || fail "z_des changed: $(cat "$tmp/station_get.log")"
    in_station "'$bin' topic echo /drone/motor_commands --count 1 --wait 5" > "$tmp/station_cmd.log" 2>&1 \
      || fail "the station cannot read /drone/motor_commands"
    finish_plant
    ;;

  check_loose)  # create-* make keys 0600 in 0700 folders; check refuses looser modes and unsigned edits
    ( umask 022
      "$bin" security create-keystore "$ks" > "$tmp/ks.log" 2>&1
      "$bin" security create-enclave "$ks" /quadcosim/plant >> "$tmp/ks.log" 2>&1 ) || fail "create-* failed"
    edir="$ks/enclaves/quadcosim/plant"
    for f in "$ks/private:700" "$ks/private/ca.key.pem:600" "$edir:700" "$edir/key.pem:600"; do
      [ "$(stat -c %a "${f%:*}")" = "${f##*:}" ] || fail "${f%:*}: mode $(stat -c %a "${f%:*}"), want ${f##*:}"
    done
    "$bin" security check "$ks" /quadcosim/plant > "$tmp/check.log" 2>&1 || fail "a fresh enclave fails the check"
    expect_problem() {  # expect_problem TEXT: security check exits 1 naming TEXT on a problem: line
      set +e
      "$bin" security check "$ks" /quadcosim/plant > "$tmp/check.log" 2>&1
      local rc=$?
      set -e
      [ "$rc" -eq 1 ] || fail "security check: expected exit 1, got $rc"
      grep -F "problem: " "$tmp/check.log" | grep -qF -- "$1" || fail "security check does not name '$1'"
    }
    for f in "$edir/key.pem:644:600" "$edir/key.pem:660:600" "$edir:755:700" "$edir:770:700" \
             "$ks/private:755:700" "$ks/private/ca.key.pem:604:600"; do
      IFS=: read -r path loose tight <<< "$f"
      chmod "$loose" "$path"
      expect_problem "$path: mode 0$loose"
      chmod "$tight" "$path"
    done
    "$bin" security check "$ks" /quadcosim/plant > "$tmp/check.log" 2>&1 || fail "check fails after the modes are fixed"
    # permissions.xml edited without signing it again: what Cyclone enforces is not what it says.
    cp "$edir/permissions.xml" "$tmp/permissions.xml"
    sed -i 's|<default>DENY</default>|<default>ALLOW</default>|' "$edir/permissions.xml"
    expect_problem "$edir/permissions.xml: differs from what permissions.p7s signs"
    cp "$tmp/permissions.xml" "$edir/permissions.xml"
    sed -i 's|<rtps_protection_kind>SIGN|<rtps_protection_kind>NONE|' "$ks/enclaves/governance.xml"
    expect_problem "$ks/enclaves/governance.xml: differs from what governance.p7s signs"
    ;;

  *) echo "unknown case $case_name"; exit 2 ;;
esac
echo "PASS [$case_name]"
