#!/usr/bin/env bash
# The extra sensors of scenarios/realism/all_sensors.yaml (docs/sensors.md) as a user meets them.
# Usage: sensors_cases.sh BINARY SOURCE_DIR CASE DOMAIN_ID
# Cases: recorded (run.mcap holds each sensor at its rate; every sample agrees with the truth of
# trajectory.csv through the ISA, WGS-84 and field formulas written again here, within the configured
# noise), dds_identical (the DDS plant publishes the same samples, bit for bit), off_by_default (the
# paper's scenarios publish none of them, and turning them on changes no other number), bad_keys (a
# wrong key or value is named), fmu_outputs (the plant FMU declares each sensor's numbers with their
# SI units; their values are checked against the plant node in FmuPlantNode's unit test).
bin="$1"; src="$2"
source "$(dirname "${BASH_SOURCE[0]}")/../lib/process_case.sh" "$3" "$4"
py=/usr/bin/python3
verify="$src/tools/mcap_verify"
scenario="$src/scenarios/realism/all_sensors.yaml"
topics=(/drone/MagneticField /drone/FluidPressure /drone/NavSatFix /drone/NavSatVelocity)

dump() {  # dump FOLDER > JSON: the sensor topics of FOLDER/run.mcap, decoded by the reference reader
  node "$verify/dump.mjs" "$1/run.mcap" "${topics[@]}"
}

case "$case_name" in
  recorded)
    bash "$verify/install.sh"
    "$bin" run "$scenario" --out "$tmp/run" --no-plots > "$tmp/run.log" 2>&1 || [ $? -eq 1 ] || fail "run failed"
    dump "$tmp/run" > "$tmp/sensors.json" || fail "the reference reader could not decode the sensors"
    "$py" - "$tmp/sensors.json" "$tmp/run/trajectory.csv" <<'PY' || fail "sensor samples disagree with the truth"
import csv, json, math, sys
topics = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
truth = {round(float(r["t"]) * 100): r for r in rows}  # by plant tick (100 Hz)
def tick(m):
    s = m["message"]["header"]["stamp"]
    return round((int(s["sec"]) * 1e9 + int(s["nanosec"])) / 1e7)
def stats(xs):
    m = sum(xs) / len(xs)
    return m, math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1))

# Rates: 15 s, ticks 0..1500: 100 Hz -> 1501, 50 Hz -> 751, 10 Hz -> 151.
for topic, n, schema in (("/drone/MagneticField", 1501, "sensor_msgs/msg/MagneticField"),
                         ("/drone/FluidPressure", 751, "sensor_msgs/msg/FluidPressure"),
                         ("/drone/NavSatFix", 151, "sensor_msgs/msg/NavSatFix"),
                         ("/drone/NavSatVelocity", 151, "geometry_msgs/msg/TwistStamped")):
    got = topics[topic]
    assert got is not None, f"{topic} not recorded"
    assert len(got["messages"]) == n, (topic, len(got["messages"]), n)
    assert got["schemaName"] == schema, (topic, got["schemaName"])

# Magnetometer: B_W = F (cos I sin D, cos I cos D, -sin I) in ENU, read in the body frame through the
# true attitude (rotate by the conjugate quaternion, written out here), minus the hard iron; what is
# left is the white noise (0.32 uT).
F, I, D = 48e-6, math.radians(63.5), math.radians(3.0)
B = (F * math.cos(I) * math.sin(D), F * math.cos(I) * math.cos(D), -F * math.sin(I))
def to_body(q, v):  # R(q)^T v for q = (w, x, y, z)
    w, x, y, z = q
    R = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    return [sum(R[r][c] * v[r] for r in range(3)) for c in range(3)]
res = [[], [], []]
for m in topics["/drone/MagneticField"]["messages"]:
    r = truth[tick(m)]
    expected = to_body([float(r[k]) for k in ("qw", "qx", "qy", "qz")], B)
    got = m["message"]["magnetic_field"]
    for i, axis in enumerate("xyz"):
        res[i].append(got[axis] - expected[i])
    assert abs(m["message"]["magnetic_field_covariance"][0] - 0.32e-6 ** 2) < 1e-20
for i, hard in enumerate((2.0e-6, -1.5e-6, 0.8e-6)):
    mean, sd = stats(res[i])
    assert abs(mean - hard) < 4 * 0.32e-6 / math.sqrt(1501), ("magnetometer mean", i, mean, hard)
    assert abs(sd - 0.32e-6) < 0.1 * 0.32e-6, ("magnetometer noise", i, sd)
print(f"magnetometer: offsets {[round(stats(r)[0] * 1e6, 3) for r in res]} uT (hard iron 2, -1.5, 0.8)")

# Barometer: ISA p = 101325 (1 - 0.0065 h / 288.15)^5.25588 at h = 488 m + z; the residual is the bias
# (turn-on sigma 20 Pa, drift 0.1 Pa/sqrt(s): a few Pa over 15 s) plus white noise of 1.2 Pa.
res = []
for m in topics["/drone/FluidPressure"]["messages"]:
    h = 488.0 + float(truth[tick(m)]["z"])
    res.append(m["message"]["fluid_pressure"] - 101325.0 * (1 - 0.0065 * h / 288.15) ** 5.25588)
    assert abs(m["message"]["variance"] - 1.44) < 1e-12
mean, sd = stats(res)
assert abs(mean) < 5 * 20, ("barometer bias", mean)
assert 1.0 < sd < 2.5, ("barometer spread (noise 1.2 Pa and a drift)", sd)
print(f"barometer: bias {mean:.2f} Pa, spread {sd:.3f} Pa")

# GNSS: 100 ms old (latency 10 ticks), no fix before 1 s of measured time; position by the WGS-84
# ellipsoid written again here (ECEF of the site plus the ENU offset, back to latitude by Heikkinen's
# closed form, not the fixed-point iteration quadcosim uses).
a, f = 6378137.0, 1 / 298.257223563
e2 = f * (2 - f)
lat0, lon0, h0 = math.radians(47.397742), math.radians(8.545594), 488.0
def ecef(lat, lon, h):
    n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1 - e2) + h) * math.sin(lat))
def geodetic(x, y, z):  # Heikkinen (1982), exact closed form
    b = a * (1 - f)
    ep2 = (a * a - b * b) / (b * b)
    p = math.hypot(x, y)
    F_ = 54 * b * b * z * z
    G = p * p + (1 - e2) * z * z - e2 * (a * a - b * b)
    c = e2 * e2 * F_ * p * p / G ** 3
    s = (1 + c + math.sqrt(c * c + 2 * c)) ** (1 / 3)
    P = F_ / (3 * (s + 1 / s + 1) ** 2 * G * G)
    Q = math.sqrt(1 + 2 * e2 * e2 * P)
    r0 = -P * e2 * p / (1 + Q) + math.sqrt(a * a / 2 * (1 + 1 / Q) - P * (1 - e2) * z * z / (Q * (1 + Q)) - P * p * p / 2)
    U = math.sqrt((p - e2 * r0) ** 2 + z * z)
    V = math.sqrt((p - e2 * r0) ** 2 + (1 - e2) * z * z)
    z0 = b * b * z / (a * V)
    return math.atan((z + ep2 * z0) / p), math.atan2(y, x), U * (1 - b * b / (a * V))
o = ecef(lat0, lon0, h0)
E = (-math.sin(lon0), math.cos(lon0), 0.0)
N = (-math.sin(lat0) * math.cos(lon0), -math.sin(lat0) * math.sin(lon0), math.cos(lat0))
U_ = (math.cos(lat0) * math.cos(lon0), math.cos(lat0) * math.sin(lon0), math.sin(lat0))
fixes = topics["/drone/NavSatFix"]["messages"]
vels = topics["/drone/NavSatVelocity"]["messages"]
err = [[], [], []]
verr = [[], [], []]
for m, v in zip(fixes, vels):
    k = tick(m)
    measured = max(k - 10, 0)
    fix = m["message"]
    if measured < 100:  # NaN coordinates: JSON has no NaN, the reader prints null
        assert fix["status"]["status"] == -1 and fix["latitude"] is None, ("no fix expected", k, fix["status"])
        assert fix["position_covariance_type"] == 0
        continue
    assert fix["status"]["status"] == 0 and fix["status"]["service"] == 1, fix["status"]
    assert fix["position_covariance_type"] == 2
    assert [round(c, 12) for c in fix["position_covariance"][::4]] == [0.64, 0.64, 2.25]
    r = truth[measured]
    p = [float(r[k_]) for k_ in ("x", "y", "z")]
    x = [o[i] + p[0] * E[i] + p[1] * N[i] + p[2] * U_[i] for i in range(3)]
    lat, lon, h = geodetic(*x)
    # errors in metres: north, east through the radii of curvature, up directly
    M = a * (1 - e2) / (1 - e2 * math.sin(lat0) ** 2) ** 1.5
    Nr = a / math.sqrt(1 - e2 * math.sin(lat0) ** 2)
    err[0].append((math.radians(fix["longitude"]) - lon) * (Nr + h0) * math.cos(lat0))
    err[1].append((math.radians(fix["latitude"]) - lat) * (M + h0))
    err[2].append(fix["altitude"] - h)
    for i, axis in enumerate("xyz"):
        verr[i].append(v["message"]["twist"]["linear"][axis] - float(r["v" + axis]))
assert len(err[0]) == 151 - 11, len(err[0])  # measured at t >= 1 s: published at ticks 110..1500
for i, sigma in enumerate((0.8, 0.8, 1.5)):
    mean, sd = stats(err[i])
    assert abs(mean) < 4 * sigma / math.sqrt(len(err[i])), ("GNSS mean", i, mean)
    assert abs(sd - sigma) < 0.25 * sigma, ("GNSS spread", i, sd, sigma)
    vmean, vsd = stats(verr[i])
    assert abs(vsd - 0.05) < 0.25 * 0.05, ("GNSS velocity spread", i, vsd)
print(f"gnss: {len(err[0])} fixes, spreads {[round(stats(e)[1], 3) for e in err]} m (0.8, 0.8, 1.5)")
PY
    echo "ok: magnetometer, barometer and GNSS recorded at their rates and agree with the truth"
    ;;

  dds_identical)
    bash "$verify/install.sh"
    "$bin" run "$scenario" --out "$tmp/in" --no-plots > "$tmp/in.log" 2>&1 || [ $? -eq 1 ] || fail "in-process run"
    timeout 300 "$bin" run "$scenario" --transport dds --out "$tmp/dds" --no-plots > "$tmp/dds.log" 2>&1 ||
      [ $? -eq 1 ] || fail "DDS run"
    dump "$tmp/in" > "$tmp/in.json"
    dump "$tmp/dds" > "$tmp/dds.json"
    "$py" - "$tmp/in.json" "$tmp/dds.json" <<'PY' || fail "the DDS plant published other samples"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for topic in a:
    ma = [m["message"] for m in a[topic]["messages"]]
    mb = [m["message"] for m in b[topic]["messages"]]
    assert len(ma) == len(mb) and len(ma) > 100, (topic, len(ma), len(mb))
    assert json.dumps(ma) == json.dumps(mb), topic  # JSON round-trips doubles exactly (NaN as NaN)
    print(f"{topic}: {len(ma)} messages, identical")
PY
    cmp "$tmp/in/trajectory.csv" "$tmp/dds/trajectory.csv" || fail "trajectories differ"
    echo "ok: the DDS plant publishes the in-process samples, bit for bit"
    ;;

  off_by_default)
    bash "$verify/install.sh"
    "$bin" run "$src/scenarios/paper/altitude_step.yaml" --out "$tmp/paper" --no-plots > "$tmp/paper.log" 2>&1 ||
      fail "paper run"
    dump "$tmp/paper" > "$tmp/paper.json"
    "$py" -c "import json,sys; d=json.load(open(sys.argv[1])); assert all(v is None for v in d.values()), d" \
      "$tmp/paper.json" || fail "the paper's scenario publishes extra sensors"
    # The same scenario without magnetometer, barometer and GNSS flies the same numbers.
    "$py" - "$scenario" "$tmp/without.yaml" <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
out, skip = [], False
for line in lines:
    if line.startswith("  magnetometer:") or line.startswith("  barometer:") or line.startswith("  gnss:"):
        skip = True
        continue
    if skip and line.startswith("    "):
        continue
    skip = False
    out.append(line)
open(sys.argv[2], "w").write("\n".join(out))
PY
    grep -q "^  magnetometer:\|^  barometer:\|^  gnss:" "$tmp/without.yaml" && fail "the sensors were not removed"
    "$bin" run "$scenario" --out "$tmp/with" --no-plots > "$tmp/with.log" 2>&1 || [ $? -eq 1 ] || fail "with"
    "$bin" run "$tmp/without.yaml" --out "$tmp/without" --no-plots > "$tmp/without.log" 2>&1 || [ $? -eq 1 ] ||
      fail "without"
    cmp "$tmp/with/trajectory.csv" "$tmp/without/trajectory.csv" ||
      fail "turning the extra sensors on changed the flight"
    echo "ok: no extra sensor unless configured; configured, they change no other number"
    ;;

  bad_keys)
    refused() {  # refused WHAT EXPECTED_TEXT COMMAND...: exit 2 naming it, nothing written
      local what="$1" expected="$2" rc
      shift 2
      set +e
      "$@" > "$tmp/refused.log" 2>&1
      rc=$?
      set -e
      [ "$rc" -eq 2 ] && grep -qF "$expected" "$tmp/refused.log" ||
        fail "$what: exit $rc, expected 2 and '$expected' in: $(cat "$tmp/refused.log")"
      echo "ok: $what -> $(grep -m1 error "$tmp/refused.log")"
    }
    edit() {  # edit SED_EXPRESSION NAME: the scenario changed by one sed expression, as $tmp/NAME.yaml
      sed "$1" "$scenario" > "$tmp/$2.yaml"
    }
    edit "s|^  gnss:|  magnetometer2: {}\n  gnss:|" unknown
    refused "an unknown sensor" "sensors.magnetometer2: unknown key; did you mean 'magnetometer'?" \
      "$bin" run "$tmp/unknown.yaml" --out "$tmp/o1" --no-plots
    edit "s|    rate_hz: 10$|    rate_hz: 30|" rate
    refused "a GNSS rate off the control ticks" "sensors.gnss.rate_hz: got 30" \
      "$bin" run "$tmp/rate.yaml" --out "$tmp/o2" --no-plots
    edit "s|    latitude_deg: 47.397742|    latitude_deg: 97|" site
    refused "a latitude of 97 deg" "environment.site.latitude_deg: got '97'" \
      "$bin" run "$tmp/site.yaml" --out "$tmp/o3" --no-plots
    ;;

  fmu_outputs)  # the plant FMU of all_sensors.yaml declares each sensor's numbers, in SI units
    "$bin" fmu export plant --scenario "$scenario" --out "$tmp/plant.fmu" > "$tmp/export.log" 2>&1 ||
      fail "fmu export plant failed: $(cat "$tmp/export.log")"
    "$py" - "$tmp/plant.fmu" <<'PY' || fail "the plant FMU's description lacks the sensors"
import math, sys, zipfile
import xml.etree.ElementTree as ET
root = ET.fromstring(zipfile.ZipFile(sys.argv[1]).read("modelDescription.xml"))
units = {u.get("name"): u.find("BaseUnit").attrib for u in root.iter("Unit")}
variables = {v.get("name"): v for v in root.iter("ScalarVariable")}
want = {"magnetometer.field[1]": "T", "magnetometer.field[3]": "T", "barometer.pressure": "Pa",
        "barometer.altitude": "m", "gnss.fix": "1", "gnss.latitude_deg": "deg", "gnss.longitude_deg": "deg",
        "gnss.altitude_m": "m", "gnss.v[3]": "m/s"}
for name, unit in want.items():
    v = variables.get(name)
    assert v is not None, f"no variable {name}"
    assert v.get("causality") == "output" and v.get("variability") == "discrete", (name, v.attrib)
    assert v.find("Real").get("unit") == unit, (name, v.find("Real").attrib)
# The units as SI base units: tesla = kg s^-2 A^-1; a degree = pi/180 rad; a pascal = kg m^-1 s^-2.
assert units["T"] == {"kg": "1", "s": "-2", "A": "-1"}, units["T"]
assert units["Pa"] == {"kg": "1", "m": "-1", "s": "-2"}, units["Pa"]
assert units["deg"]["rad"] == "1" and abs(float(units["deg"]["factor"]) - math.pi / 180) < 1e-18, units["deg"]
outputs = [u.get("index") for u in root.find("ModelStructure").find("Outputs")]
assert len(outputs) == len(set(outputs)) and len(outputs) >= 30, len(outputs)
print(f"ok: {len(want)} sensor outputs checked, {len(outputs)} outputs in all")
PY
    ;;

  *) fail "unknown case $case_name" ;;
esac
