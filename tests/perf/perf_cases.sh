#!/usr/bin/env bash
# Swarm runs and the bench smoke test. Usage: perf_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# DDS cases run on their own ROS_DOMAIN_ID with localhost-only discovery and end every process they
# started (trap), also on failure. Speed is never asserted here: bench prints figures.
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
py=/usr/bin/python3
grid="$src/scenarios/swarm/grid_takeoff.yaml"

case "$case_name" in
  bench_quick)  # every key present, every figure positive and finite, the machine described
    "$bin" bench --json --quick > "$tmp/bench.json" 2> "$tmp/bench.log" || fail "bench exited non-zero"
    "$py" - "$tmp/bench.json" <<'PY' || fail "bench JSON incomplete"
import json, math, sys
j = json.loads(open(sys.argv[1]).read())
for k in ["inproc_rtf", "baseline_rtf", "dds_lockstep_rtf", "dds_cmd_roundtrip_us_p50", "dds_cmd_roundtrip_us_p99",
          "realtime_period_jitter_us_p99", "swarm_inproc_vehicles_at_rt", "swarm_dds_vehicles_at_rt"]:
    v = j[k]
    assert isinstance(v, (int, float)) and math.isfinite(v) and v > 0, (k, v)
assert j["dds_cmd_roundtrip_us_p99"] >= j["dds_cmd_roundtrip_us_p50"], "p99 below p50"
# Two CPUs or more: the DDS figures again with plant and controller pinned apart.
if j["pinned_cpus"] is not None:
    assert len(j["pinned_cpus"]) == 2 and j["pinned_cpus"][0] != j["pinned_cpus"][1], j["pinned_cpus"]
    for k in ["dds_lockstep_rtf_pinned", "swarm_dds_vehicles_at_rt_pinned"]:
        v = j[k]
        assert isinstance(v, (int, float)) and math.isfinite(v) and v > 0, (k, v)
m = j["machine"]
for k in ["cpu_model", "cores", "kernel", "compiler"]:
    assert m[k], k
assert m["cores"] >= 1
PY
    ;;
  swarm_inproc)  # 100 vehicles: each at its own cell and height, recorded vehicles judged
    "$bin" run "$grid" --vehicles 100 --out "$tmp/s" --no-plots > "$tmp/run.log" 2>&1 || fail "swarm run failed"
    [ "$(wc -l < "$tmp/s/vehicles.csv")" -eq 101 ] || fail "vehicles.csv should have 100 rows"
    [ -s "$tmp/s/uav0000/trajectory.csv" ] && [ -s "$tmp/s/uav0063/metrics.json" ] || fail "recorded vehicles missing"
    "$py" - "$tmp/s" <<'PY' || fail "swarm outcome wrong"
import csv, json, math, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
assert s["vehicles"] == 100 and s["vehicles_in_safety"] == 0 and s["vehicles_non_finite"] == 0, s
rows = list(csv.DictReader(open(d + "/vehicles.csv")))
assert [r["namespace"] for r in rows[:3]] == ["/uav0000", "/uav0001", "/uav0002"]
for i, r in enumerate(rows):
    # 10 columns (ceil(sqrt(100))), 2 m apart; heights 5, 6, 7 m by index mod 3.
    want = ((i % 10) * 2.0, (i // 10) * 2.0, 5.0 + (i % 3))
    got = tuple(float(r[k]) for k in ("x_m", "y_m", "z_m"))
    assert all(abs(g - w) < 0.02 for g, w in zip(got, want)), (i, got, want)
PY
    # Bad input names the key and exits 2.
    printf 'swarm:\n  vehicles: 4\n  record_vehicles: [7]\n' > "$tmp/bad.yaml"
    set +e; "$bin" run "$tmp/bad.yaml" --out "$tmp/bad" --no-plots > "$tmp/bad.log" 2>&1; rc=$?; set -e
    [ "$rc" -eq 2 ] || fail "bad swarm section: exit $rc, expected 2"
    grep -q "swarm.record_vehicles\[0\]" "$tmp/bad.log" || fail "error does not name swarm.record_vehicles[0]"
    ;;
  swarm_saturation)  # recorded vehicles are judged against analysis.limits as `run` judges one vehicle
    # A 1 rad yaw step from hover clamps rotors 2 and 4 for about 1.5 s; max_saturated_s 0.5 fails it.
    cat > "$tmp/yaw.yaml" <<'YAML'
name: swarm_yaw
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 6}
initial: {position_m: [0, 0, 10], hover: true}
controller: {mode: attitude, z_des: 10, yaw_des: 1.0}
analysis:
  steps:
    - channel: z
      at_s: 0
  limits: {max_saturated_s: 0.5}
YAML
    printf 'swarm: {vehicles: 3, record_vehicles: [0, 2]}\n' | cat "$tmp/yaw.yaml" - > "$tmp/swarm.yaml"
    set +e
    "$bin" run "$tmp/swarm.yaml" --out "$tmp/s" --no-plots > "$tmp/s.log" 2>&1; rc=$?
    "$bin" run "$tmp/yaw.yaml" --out "$tmp/one" --no-plots > "$tmp/one.log" 2>&1; rc1=$?
    set -e
    [ "$rc" -eq 1 ] || { cat "$tmp/s.log"; fail "swarm over its saturation limit: exit $rc, expected 1"; }
    [ "$rc1" -eq 1 ] || { cat "$tmp/one.log"; fail "single run over its saturation limit: exit $rc1, expected 1"; }
    grep -q "run: uav0002: warning: rotor saturation: rotors 2, 4" "$tmp/s.log" || { cat "$tmp/s.log"; fail "no warning"; }
    "$py" - "$tmp/s" "$tmp/one" <<'PY' || fail "recorded vehicles' saturation wrong"
import csv, json, sys
s = json.load(open(sys.argv[1] + "/summary.json")); one = json.load(open(sys.argv[2] + "/metrics.json"))
rec = s["recorded"]
assert [(r["vehicle"], r["namespace"], r["passed"]) for r in rec] == [(0, "/uav0000", False), (2, "/uav0002", False)], rec
for r in rec:
    m = json.load(open(sys.argv[1] + r["namespace"] + "/metrics.json"))
    assert m["saturation"]["figures"] == r["saturation"] and m["passed"] is False, (m["saturation"], r)
    assert m["saturation"]["criteria"][0]["passed"] is False and m["steps"][0]["passed"] is True
    # Counted here from the vehicle's own CSV rows (period 0.01 s).
    rows = list(csv.DictReader(open(sys.argv[1] + r["namespace"] + "/trajectory.csv")))
    n = sum(1 for row in rows if "1" in (row["sat1"], row["sat2"], row["sat3"], row["sat4"]))
    assert n * 0.01 > 1.0 and abs(n * 0.01 - r["saturation"]["saturated_s"]) < 1e-9, (n, r)
# Vehicle 0 flies at the scenario's own place: the figures of the single-vehicle run, bit for bit.
assert rec[0]["saturation"] == one["saturation"]["figures"], (rec[0], one["saturation"])
PY
    ;;
  swarm_dds_identical)  # 6 vehicles over DDS (one plant and one controller process, 2 threads each)
    "$bin" run "$grid" --vehicles 6 --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || fail "in-process swarm failed"
    "$bin" run "$grid" --vehicles 6 --out "$tmp/dds" --no-plots --transport dds > "$tmp/dds.log" 2>&1 \
      || fail "DDS swarm failed"
    cmp "$tmp/in/vehicles.csv" "$tmp/dds/vehicles.csv" || fail "final states differ"
    cmp "$tmp/in/uav0000/trajectory.csv" "$tmp/dds/uav0000/trajectory.csv" || fail "recorded trajectory differs"
    [ "$(wc -l < "$tmp/dds/uav0000/trajectory.csv")" -gt 1000 ] || fail "trajectory too short"
    # Best-effort sensor topics (ROS sensor data QoS), the plant writing the swarm's files itself
    # into a folder it makes: the same numbers.
    "$bin" controller --scenario "$grid" --vehicles 6 --sensor-qos > "$tmp/be_c.log" 2>&1 &
    pids+=($!)
    "$bin" plant --scenario "$grid" --vehicles 6 --sensor-qos --swarm-out "$tmp/be" > "$tmp/be_p.log" 2>&1 \
      || fail "DDS swarm with --sensor-qos failed"
    cmp "$tmp/in/vehicles.csv" "$tmp/be/vehicles.csv" || fail "final states differ with --sensor-qos"
    cmp "$tmp/in/uav0000/trajectory.csv" "$tmp/be/uav0000/trajectory.csv" || fail "trajectory differs with --sensor-qos"
    ;;
  *) echo "unknown case $case_name"; exit 2 ;;
esac
echo "PASS [$case_name]"
