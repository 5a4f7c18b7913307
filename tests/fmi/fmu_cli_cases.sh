#!/usr/bin/env bash
# `quadcosim fmu export` and `quadcosim fmu info`, one case per CTest test: the FMU's layout, what its
# modelDescription.xml declares (read with Python's zipfile and xml.etree, checked against the lists
# `quadcosim params` prints), reproducibility, and bad input.
#   usage: fmu_cli_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE DOMAIN
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
P="$SRC/scenarios/paper"

# check_fmu FMU KIND FMI_VERSION SCENARIO_OR_EMPTY: the layout and the declarations of an exported FMU.
check_fmu() {
  "$QC" params --vehicle --markdown > "$TMP/vehicle.md"
  "$QC" params --controller paper > "$TMP/controller.txt"
  "$PY" - "$@" "$TMP/vehicle.md" "$TMP/controller.txt" "$TMP/export.txt" <<'PYEOF'
import json, math, re, struct, sys, zipfile
import xml.etree.ElementTree as ET

fmu, kind, version, scenario, vehicle_md, controller_txt, export_txt = sys.argv[1:8]
v3 = version == "3"
errors = []
def check(cond, what):
    if not cond:
        errors.append(what)

z = zipfile.ZipFile(fmu)
check(z.testzip() is None, "a zip entry is corrupt")
names = set(z.namelist())
ident = "quadcosim_" + kind
platform = "x86_64-linux" if v3 else "linux64"
so = f"binaries/{platform}/{ident}.so"
for need in ["modelDescription.xml", so, "resources/quadcosim.json"]:
    check(need in names, f"missing {need} (entries: {sorted(names)})")
other = "binaries/linux64/" if v3 else "binaries/x86_64-linux/"
check(not any(n.startswith(other) for n in names), f"{other} does not belong in an FMI {version} FMU")

# The binary: an ELF shared object (e_type 3), byte for byte the library the command says it packed.
lib = z.read(so)
check(lib[:4] == b"\x7fELF" and struct.unpack_from("<H", lib, 16)[0] == 3, f"{so} is not an ELF shared object")
packed_from = re.search(r"from (\S+)", open(export_txt).read()).group(1)
check(open(packed_from, "rb").read() == lib, f"{so} differs from {packed_from}")

config = json.loads(z.read("resources/quadcosim.json"))
root = ET.fromstring(z.read("modelDescription.xml"))
check(root.tag == "fmiModelDescription", "root element")
check(root.get("fmiVersion") == ("3.0" if v3 else "2.0"), f"fmiVersion {root.get('fmiVersion')}")
token = root.get("instantiationToken" if v3 else "guid")
check(re.fullmatch(r"\{[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}\}", token or ""),
      f"GUID/token {token!r} is not {{8-4-4-4-12}} hex")
check(config.get("guid") == token, "resources/quadcosim.json holds another GUID than modelDescription.xml")
check(root.get("variableNamingConvention") == "structured", "naming convention")
check(root.get("generationTool", "").startswith("quadcosim "), "generationTool")
cs = root.find("CoSimulation")
check(cs is not None and cs.get("modelIdentifier") == ident, "CoSimulation modelIdentifier")
# A step must be a whole number of periods: the FMU cannot take any step, so it must not say it can.
check(cs is not None and cs.get("canHandleVariableCommunicationStepSize", "false") == "false",
      "canHandleVariableCommunicationStepSize should be false")
check(cs is not None and cs.get("canGetAndSetFMUState" if v3 else "canGetAndSetFMUstate") == "true",
      "the FMU saves and restores its state: canGetAndSetFMUstate should be true")
period = 0.01 if kind == "plant" else 0.02  # the paper's rates: plant 100 Hz, controller 50 Hz
exp = root.find("DefaultExperiment")
check(exp is not None and float(exp.get("stepSize")) == period, "DefaultExperiment stepSize")
if scenario:
    check(float(exp.get("stopTime")) == 15.0, "DefaultExperiment stopTime: the scenario's duration 15 s")

# Units: each used is defined, with the SI exponents worked out here.
units = {u.get("name"): u for u in root.iter("Unit")}
expected_base = {"m": {"m": "1"}, "rad/s": {"s": "-1", "rad": "1"}, "m/s2": {"m": "1", "s": "-2"},
                 "kg": {"kg": "1"}, "kg m^2": {"kg": "1", "m": "2"}, "N/(rad/s)^2": {"kg": "1", "m": "1", "rad": "-2"}}
for name, base in expected_base.items():
    if name in units:
        check(units[name].find("BaseUnit").attrib == base, f"unit {name}: {units[name].find('BaseUnit').attrib}")

# Variables: FMI 2 ScalarVariable + typed child; FMI 3 typed elements.
variables = []  # (index 1-based, name, vr, type, attributes incl. the typed ones)
if v3:
    for i, e in enumerate(root.find("ModelVariables"), 1):
        a = dict(e.attrib)
        variables.append((i, a["name"], int(a["valueReference"]), e.tag, a))
else:
    for i, sv in enumerate(root.find("ModelVariables").findall("ScalarVariable"), 1):
        child = sv[0]
        a = dict(sv.attrib)
        a.update(child.attrib)
        variables.append((i, a["name"], int(a["valueReference"]), child.tag, a))
by_name = {v[1]: v for v in variables}
real = "Float64" if v3 else "Real"
for _, name, _, _, a in variables:
    if "unit" in a:
        check(a["unit"] in units, f"{name}: unit {a['unit']} is not in UnitDefinitions")
    if a.get("causality") in ("input", "parameter"):
        check("start" in a or v3 and a.get("causality") == "parameter", f"{name}: no start value")

def declared(name, causality, unit=None, typ=real):
    v = by_name.get(name)
    check(v is not None, f"{name} is not declared")
    if v is None:
        return None
    a = v[4]
    check(a.get("causality") == causality, f"{name}: causality {a.get('causality')}, expected {causality}")
    check(v[3] == typ, f"{name}: type {v[3]}, expected {typ}")
    if unit is not None:
        check(a.get("unit") == unit, f"{name}: unit {a.get('unit')}, expected {unit}")
    return a

omega = [f"omega_cmd[{i}]" for i in range(1, 5)]
vec = lambda base, n: [f"{base}[{i}]" for i in range(1, n + 1)]
sensors = [(vec("p_W", 3), "m"), (vec("v_W", 3), "m/s"), (vec("q_WB", 4), "1"), (vec("w_B", 3), "rad/s"),
           (vec("f_B", 3), "m/s2")]
if kind == "plant":
    for n in omega:
        declared(n, "input", "rad/s")
    for group, unit in sensors + [(vec("euler", 3), "rad"), (vec("omega", 4), "rad/s")]:
        for n in group:
            declared(n, "output", unit)
    # Every numeric vehicle parameter `quadcosim params --vehicle` lists, with its unit and default.
    rows = [l.strip().strip("|").split("|") for l in open(vehicle_md) if l.startswith("| `")]
    count = 0
    for key, unit, _rng, default in (r[:4] for r in rows):
        key, unit, default = key.strip().strip("`"), unit.strip(), default.strip()
        try:
            value = float(default)
        except ValueError:
            continue  # a choice (layout, motor model) or the spin signs: not an FMU parameter
        count += 1
        a = declared("vehicle." + key, "parameter", unit if unit else None)
        if a is not None:
            check(a.get("variability") == "fixed", f"vehicle.{key}: variability {a.get('variability')}")
            check(math.isclose(float(a["start"]), value, rel_tol=1e-6, abs_tol=1e-30),
                  f"vehicle.{key}: start {a['start']}, params says {default}")
            if not unit:
                check("unit" not in a, f"vehicle.{key}: a unit where params lists none")
    check(count >= 20, f"only {count} numeric vehicle parameters read from params --vehicle")
    for n in vec("initial.p_W", 3) + vec("initial.omega", 4):
        declared(n, "parameter")
    for n in ["realism.wind", "realism.rotor_faults", "realism.sensor_noise"]:
        declared(n, "parameter", typ="Boolean")
    declared("realism.seed", "parameter", typ="Int32" if v3 else "Integer")
else:
    for n in omega:
        a = declared(n, "output", "rad/s")
        check(a is None or a.get("variability") == "discrete", f"{n}: a sampled output is discrete")
    for group, unit in sensors:
        for n in group:
            declared(n, "input", unit)
    a = declared("ref.p_W[3]", "input", "m")
    if scenario:  # altitude_step's schedule sets z_des = 10 at t = 0: the reference starts there
        check(a is not None and float(a["start"]) == 10.0, f"ref.p_W[3] start {a and a.get('start')}, expected 10")
    # Every controller parameter `quadcosim params --controller paper` lists (the node's own setpoint
    # parameters are the ref.* inputs instead), with its unit.
    lines = open(controller_txt).read().splitlines()
    header = lines[0]
    cols = [header.index(c) for c in ("name", "unit", "range", "default")]
    node = {"mode", "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des", "stale_limit", "safety_mode"}
    count = 0
    for line in lines[1:]:
        name = line[cols[0]:cols[1]].strip()
        unit = line[cols[1]:cols[2]].strip()
        if not name or name in node:
            continue
        count += 1
        if unit:
            declared("controller." + name, "parameter", unit)
        else:  # dimensionless number (Real) or a choice (String)
            v = by_name.get("controller." + name)
            check(v is not None and v[4].get("causality") == "parameter" and v[3] in (real, "String"),
                  f"controller.{name} is not declared as a Real or String parameter")
    check(count >= 5, f"only {count} controller parameters read from params --controller paper")

# ModelStructure: exactly the outputs, each once; initial unknowns are the calculated outputs.
outputs = [v for v in variables if v[4].get("causality") == "output"]
ms = root.find("ModelStructure")
if v3:
    listed = [int(e.get("valueReference")) for e in ms.findall("Output")]
    check(all(e.get("dependencies") == "" for e in ms.findall("Output")),
          "every Output should declare dependencies=\"\" (no direct feedthrough)")
    check(sorted(listed) == sorted(v[2] for v in outputs), "ModelStructure Output valueReferences != the outputs")
    init = [int(e.get("valueReference")) for e in ms.findall("InitialUnknown")]
    check(sorted(init) == sorted(v[2] for v in outputs if v[4].get("initial", "calculated") != "exact"),
          "InitialUnknown != the calculated outputs")
    check(sum(1 for v in variables if v[4].get("causality") == "independent") == 1, "one independent variable")
    vrs = [v[2] for v in variables]
    check(len(set(vrs)) == len(vrs), "FMI 3 value references are not unique")
else:
    listed = [int(u.get("index")) for u in ms.find("Outputs").findall("Unknown")]
    check(all(u.get("dependencies") == "" for u in ms.find("Outputs").findall("Unknown")),
          "every Outputs/Unknown should declare dependencies=\"\" (no direct feedthrough)")
    check(sorted(listed) == sorted(v[0] for v in outputs), "ModelStructure Outputs indices != the outputs")
    iu = ms.find("InitialUnknowns")
    init = [int(u.get("index")) for u in iu.findall("Unknown")] if iu is not None else []
    check(init == sorted(v[0] for v in outputs if v[4].get("initial", "calculated") != "exact"),
          "InitialUnknowns != the calculated outputs, by index")
    check(root.get("numberOfEventIndicators") == "0", "numberOfEventIndicators")
    for typ in ("Real", "Integer", "Boolean", "String"):
        vrs = [v[2] for v in variables if v[3] == typ]
        check(len(set(vrs)) == len(vrs), f"FMI 2 {typ} value references are not unique")

if errors:
    print("\n".join(errors))
    sys.exit(1)
print(f"ok: {fmu}: {len(variables)} variables, {len(outputs)} outputs")
PYEOF
}

# export KIND VERSION [SCENARIO]: exports into $TMP/KIND$VERSION.fmu and checks it.
export_and_check() {
  local kind=$1 version=$2 scenario=${3:-} out="$TMP/$1$2.fmu"
  local args=(fmu export "$kind" --fmi "$version" --out "$out")
  [ -n "$scenario" ] && args+=(--scenario "$scenario")
  "$QC" "${args[@]}" > "$TMP/export.txt" || fail "fmu export $kind --fmi $version exited $?"
  grep -q "^wrote $out: FMI $version.0 co-simulation FMU" "$TMP/export.txt" || fail "no summary: $(cat "$TMP/export.txt")"
  check_fmu "$out" "$kind" "$version" "$scenario" || fail "$kind FMI $version: the FMU is not as promised"
}

# expect_error CODE TEXT ARGS...: quadcosim ARGS exits CODE and says TEXT on stderr.
expect_error() {
  local code=$1 text=$2
  shift 2
  local rc=0
  "$QC" "$@" > "$TMP/out.txt" 2> "$TMP/err.txt" || rc=$?
  [ "$rc" = "$code" ] || fail "quadcosim $*: exit $rc, expected $code ($(cat "$TMP/err.txt"))"
  grep -qF -- "$text" "$TMP/err.txt" || fail "quadcosim $*: stderr lacks '$text': $(cat "$TMP/err.txt")"
}

case "$CASE" in
  export_plant_fmi2) export_and_check plant 2 "$P/altitude_step.yaml" ;;
  export_plant_fmi3) export_and_check plant 3 "$P/altitude_step.yaml" ;;
  export_controller_fmi2) export_and_check controller 2 "$P/altitude_step.yaml" ;;
  export_controller_fmi3) export_and_check controller 3 ;;

  export_controller_trajectory)  # a controller exported from a scenario with a trajectory carries it
    T="$SRC/scenarios/tracking"
    # kind: file, written here: one segment from (1, 0, 2) moving +0.5 m/s in x for 4 s, from t = 1 s.
    {
      printf 'Duration'; for a in x y z yaw; do for i in 0 1 2 3 4 5 6 7; do printf ',%s^%s' $a $i; done; done; echo
      echo "4,1,0.5,0,0,0,0,0,0,0,0,0,0,0,0,0,0,2,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0"
    } > "$TMP/line.csv"
    sed '/^trajectory:/,/^analysis:/c\trajectory:\n  kind: file\n  path: line.csv\n  start_s: 1\nanalysis:' \
      "$T/circle_se3.yaml" > "$TMP/file.yaml"
    grep -q 'path: line.csv' "$TMP/file.yaml" || fail "could not write file.yaml"
    for s in "$T/circle_se3.yaml" "$T/figure8_paper.yaml" "$T/waypoints_se3.yaml" "$TMP/file.yaml"; do
      name=$(basename "$s" .yaml)
      "$QC" fmu export controller --scenario "$s" --fmi 3 --out "$TMP/$name.fmu" > "$TMP/$name.txt" \
        || fail "fmu export controller --scenario $s exited $?"
      grep -q "^  reference: " "$TMP/$name.txt" || fail "$name: the export names no reference: $(cat "$TMP/$name.txt")"
    done
    "$QC" fmu export plant --scenario "$T/circle_se3.yaml" --out "$TMP/plant.fmu" > /dev/null || fail "plant export exited $?"
    "$QC" fmu export controller --scenario "$P/altitude_step.yaml" --out "$TMP/steps.fmu" > /dev/null || fail "export exited $?"
    "$PY" - "$TMP" <<'PYEOF' || fail "the FMUs do not carry their trajectories as promised"
import json, sys, zipfile, xml.etree.ElementTree as E
tmp = sys.argv[1]
def read(name):
    z = zipfile.ZipFile(f"{tmp}/{name}.fmu")
    variables = {v.get("name"): v for v in E.fromstring(z.read("modelDescription.xml")).iter("*")
                 if v.get("valueReference") is not None}
    return json.loads(z.read("resources/quadcosim.json")), variables
def start(variables, name):
    v = variables[name]
    return float(v.get("start") if v.get("start") is not None else v[0].get("start"))
# The scenario's keys and values (scenarios/tracking/*.yaml), and where each trajectory starts.
expected = {
    "circle_se3": ({"kind": "circle", "radius_m": 2.0, "period_s": 10.0, "altitude_m": 5.0, "ramp_s": 2.0}, (2, 0, 5)),
    "figure8_paper": ({"kind": "figure8", "amplitude_m": [2.0, 1.0]}, (0, 0, 3)),  # starts at its centre
    "waypoints_se3": ({"kind": "waypoints", "method": "min_snap"}, (0, 0, 0)),
    "file": ({"kind": "polynomial", "start_s": 1.0}, (1, 0, 2)),
}
for name, (keys, p0) in expected.items():
    config, variables = read(name)
    t = config.get("trajectory")
    assert t is not None, f"{name}: no trajectory in quadcosim.json"
    for k, v in keys.items():
        assert t[k] == v, f"{name}: trajectory.{k} = {t[k]}, expected {v}"
    ext = variables.get("ref.external")
    assert ext is not None and ext.tag == "Boolean", f"{name}: no Boolean ref.external"
    assert (ext.get("causality"), ext.get("variability"), ext.get("start")) == ("parameter", "fixed", "false"), ext.attrib
    if p0 is not None:
        got = tuple(start(variables, f"ref.p_W[{i}]") for i in (1, 2, 3))
        assert got == p0, f"{name}: ref.p_W starts at {got}, expected {p0}"
config, _ = read("waypoints_se3")
assert len(config["trajectory"]["points"]) == 6 and config["trajectory"]["points"][3]["position_m"] == [4.0, 4.0, 4.0]
config, _ = read("file")
seg = config["trajectory"]["segments"]
assert len(seg) == 1 and seg[0]["duration_s"] == 4.0 and seg[0]["x"][:2] == [1.0, 0.5] and seg[0]["z"][0] == 2.0, seg
for name in ("plant", "steps"):  # no trajectory: no key, no switch
    config, variables = read(name)
    assert "trajectory" not in config and "ref.external" not in variables, name
print("ok: circle, figure8, waypoints and file carried; plant and step FMUs without")
PYEOF
    ;;

  # The exported FMUs run by an importer written here (Python ctypes over the FMI C API, nothing of
  # quadcosim but the .fmu), against closed forms: plant under constant rotor speeds, controller's first command.
  run_plant_fmi2 | run_plant_fmi3 | run_controller_fmi2 | run_controller_fmi3)
    kind=${CASE#run_}
    kind=${kind%_fmi*}
    version=${CASE##*fmi}
    args=(fmu export "$kind" --fmi "$version" --out "$TMP/x.fmu")
    [ "$kind" = controller ] && args+=(--scenario "$P/altitude_step.yaml")  # reference z = 10 m from t = 0
    "$QC" "${args[@]}" > /dev/null || fail "fmu export exited $?"
    "$PY" "$(dirname "${BASH_SOURCE[0]}")/run_exported_fmu.py" "$TMP/x.fmu" "$kind" || fail "the FMU did not run as expected"
    ;;

  info_third_party)  # an FMU quadcosim did not write: the point mass test FMU of tests/fmi (FMI 2 and 3)
    build_fmus=${5:?the build folder of tests/fmi}
    for f in point_mass point_mass3; do
      [ -f "$build_fmus/$f.fmu" ] || { echo "SKIPPED: $build_fmus/$f.fmu is not built (target fmi_test_fmus)"; exit 77; }
      "$QC" fmu info "$build_fmus/$f.fmu" > "$TMP/$f.txt" || fail "fmu info $f.fmu exited $?"
    done
    grep -Eq "^FMI version +2.0 co-simulation$" "$TMP/point_mass.txt" || fail "point_mass: FMI version"
    grep -Eq "^FMI version +3.0 co-simulation$" "$TMP/point_mass3.txt" || fail "point_mass3: FMI version"
    grep -Eq "^binaries +linux64 \(runs here: linux64/point_mass.so\)$" "$TMP/point_mass.txt" || fail "point_mass: binaries"
    grep -Eq "^binaries +x86_64-linux \(runs here" "$TMP/point_mass3.txt" || fail "point_mass3: binaries"
    "$PY" - "$build_fmus/point_mass/modelDescription.xml" "$TMP/point_mass.txt" <<'PYEOF' || fail "info lacks a variable"
import re, sys, xml.etree.ElementTree as ET
info = open(sys.argv[2]).read()
for sv in ET.parse(sys.argv[1]).getroot().iter("ScalarVariable"):
    row = re.search(r"^" + re.escape(sv.get("name")) + r" +(\d+) +(\w+) ", info, re.M)
    assert row and row.groups() == (sv.get("valueReference"), sv.get("causality", "local")), sv.get("name")
PYEOF
    ;;

  info)  # `fmu info` prints what the XML declares
    export_and_check plant 2
    "$QC" fmu info "$TMP/plant2.fmu" > "$TMP/info.txt" || fail "fmu info exited $?"
    guid=$("$PY" -c "import sys,zipfile,xml.etree.ElementTree as E; print(E.fromstring(zipfile.ZipFile(sys.argv[1]).read('modelDescription.xml')).get('guid'))" "$TMP/plant2.fmu")
    grep -Eq "^FMI version +2.0 co-simulation$" "$TMP/info.txt" || fail "no FMI version: $(head "$TMP/info.txt")"
    grep -Eq "^guid +\\$guid$" "$TMP/info.txt" || fail "no guid $guid"
    grep -Eq "^modelIdentifier +quadcosim_plant$" "$TMP/info.txt" || fail "no modelIdentifier"
    grep -Eq "^binaries +linux64 \(runs here" "$TMP/info.txt" || fail "no binaries line"
    for i in 1 2 3 4; do
      grep -Eq "^omega_cmd\[$i\] +[0-9]+ +input +continuous +Real +rad/s +0 " "$TMP/info.txt" ||
        fail "omega_cmd[$i] row: $(grep "omega_cmd\[$i\]" "$TMP/info.txt")"
    done
    grep -Eq "^p_W\[3\] +[0-9]+ +output +continuous +Real +m +- " "$TMP/info.txt" || fail "p_W[3] row"
    grep -Eq "^vehicle.mass_kg +[0-9]+ +parameter +fixed +Real +kg +1.96 " "$TMP/info.txt" || fail "mass row"
    export_and_check controller 3
    "$QC" fmu info "$TMP/controller3.fmu" > "$TMP/info3.txt" || fail "fmu info (FMI 3) exited $?"
    grep -Eq "^instantiationToken +\{" "$TMP/info3.txt" || fail "no instantiationToken"
    grep -Eq "^omega_cmd\[1\] +[0-9]+ +output +discrete +Float64 +rad/s " "$TMP/info3.txt" || fail "FMI 3 omega_cmd row"
    ;;

  reproducible)  # the same configuration gives the same bytes; another one another GUID
    "$QC" fmu export plant --scenario "$P/roll_step.yaml" --out "$TMP/a.fmu" > /dev/null
    "$QC" fmu export plant --scenario "$P/roll_step.yaml" --out "$TMP/b.fmu" > /dev/null
    cmp -s "$TMP/a.fmu" "$TMP/b.fmu" || fail "two exports of one scenario differ"
    sed 's/^  position_m: .*/  position_m: [0, 0, 3]/' "$P/roll_step.yaml" > "$TMP/higher.yaml"
    cmp -s "$P/roll_step.yaml" "$TMP/higher.yaml" && fail "test setup: the initial position was not changed"
    "$QC" fmu export plant --scenario "$TMP/higher.yaml" --out "$TMP/c.fmu" > /dev/null
    "$PY" - "$TMP/a.fmu" "$TMP/c.fmu" <<'PYEOF' || fail "a changed scenario kept its GUID or start value"
import sys, zipfile, xml.etree.ElementTree as E
def md(p):
    return E.fromstring(zipfile.ZipFile(p).read("modelDescription.xml"))
a, c = md(sys.argv[1]), md(sys.argv[2])
assert a.get("guid") != c.get("guid"), a.get("guid")
start = lambda r: [sv[0].get("start") for sv in r.iter("ScalarVariable") if sv.get("name") == "initial.p_W[3]"][0]
assert (start(a), start(c)) == ("10", "3"), (start(a), start(c))  # roll_step starts hovering at 10 m
PYEOF
    ;;

  quadrotor_unchanged)  # the paper's FMUs declare what they always did, byte for byte (GUID included)
    # sha256 of modelDescription.xml and resources/quadcosim.json, from the exports before the FMUs
    # were sized by the rotor count (commit 64ebb29): the rotors past four must not move a byte of them.
    while read -r kind version xml json; do
      "$QC" fmu export "$kind" --fmi "$version" --scenario "$P/altitude_step.yaml" --out "$TMP/q.fmu" > /dev/null \
        || fail "fmu export $kind --fmi $version failed"
      "$PY" - "$TMP/q.fmu" "$xml" "$json" <<'PYEOF' || fail "$kind FMI $version: the quadrotor's FMU changed"
import hashlib, sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for entry, want in (("modelDescription.xml", sys.argv[2]), ("resources/quadcosim.json", sys.argv[3])):
    got = hashlib.sha256(z.read(entry)).hexdigest()
    assert got == want, f"{entry}: sha256 {got}, expected {want}"
PYEOF
    done <<'EOF2'
plant 2 931a2d57fb7c16ad39fd8b9569cb8d3b07df0d2564f546fc799a8320c54a6a8f d8aaefd524073b6cee55543b7f08127b29f719dc352465836de51388ebefad51
plant 3 20a98b3b51034e7f898847bedb2bf48ee4ccf85b82d145b5c5953a7896a14864 3c1ba8f4761fb8d1f38762e3874db2c01d0e67413d4728dbb3177d8febbce863
controller 2 a71065d04fb507574d59d320ecd5835fedb1c51556ebf9ce06d4bd4c907536ee a627c34cf5a909d88fc45d054490b1c720152dd1506821769a1be69d80374e17
EOF2
    ;;

  export_rotors)  # a hexarotor's and a custom octorotor's FMUs: one command per rotor, the rotors in the JSON
    "$QC" fmu export plant --scenario "$P/altitude_step.yaml" --out "$TMP/quad.fmu" > /dev/null || fail "quad export"
    for spec in "plant 2 tracking/circle_se3_firefly" "plant 3 tracking/circle_se3_firefly" \
                "controller 2 tracking/circle_se3_firefly" "controller 3 tracking/circle_se3_firefly" \
                "plant 2 examples/octo_custom_step" "controller 3 examples/octo_custom_step"; do
      read -r kind version scenario <<< "$spec"
      out="$TMP/$kind$version.fmu"
      "$QC" fmu export "$kind" --fmi "$version" --scenario "$SRC/scenarios/$scenario.yaml" --out "$out" > "$TMP/export.txt" \
        || fail "fmu export $kind --fmi $version --scenario $scenario exited $?"
      "$PY" - "$out" "$kind" "$version" "$TMP/quad.fmu" <<'PYEOF' || fail "$kind FMI $version of $scenario"
import json, sys, zipfile
import xml.etree.ElementTree as ET
fmu, kind, version, quad = sys.argv[1:5]
def variables(path):
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    elems = root.find("ModelVariables")
    elems = list(elems) if version == "3" else elems.findall("ScalarVariable")
    return {e.get("name"): (int(e.get("valueReference")), e.get("causality")) for e in elems}, root
config = json.loads(zipfile.ZipFile(fmu).read("resources/quadcosim.json"))
vehicle = config["vehicle"]
n = len(vehicle["spin"])
custom = vehicle["layout"] == "custom"
assert (vehicle["layout"], n) in (("hex_x", 6), ("custom", 8)), (vehicle["layout"], n)
assert ("rotors" in vehicle) == custom
if custom:  # the scenario's X8: upper and lower rotors 8 cm apart on four arms
    assert [r["position_m"][2] for r in vehicle["rotors"]] == [0.04, -0.04] * 4, vehicle["rotors"]
    assert [r["spin"] for r in vehicle["rotors"]] == vehicle["spin"] == [1, -1, -1, 1, 1, -1, -1, 1]
assert len(config["initial"]["omega"]) == n
got, root = variables(fmu)
side = "input" if kind == "plant" else "output"
commands = sorted((vr, name) for name, (vr, c) in got.items() if name.startswith("omega_cmd"))
assert [name for _, name in commands] == [f"omega_cmd[{i}]" for i in range(1, n + 1)], commands
assert all(got[name][1] == side for _, name in commands)
if kind == "plant":
    for i in range(1, n + 1):
        assert got[f"omega[{i}]"][1] == "output" and got[f"initial.omega[{i}]"][1] == "parameter", i
    assert f"omega[{n + 1}]" not in got
    # Each variable of the quadrotor's plant FMU keeps its value reference; rotors 5..N come after `period`.
    if version == "2":
        same, _ = variables(quad)
        moved = [name for name, (vr, _) in same.items() if got.get(name, (None,))[0] != vr]
        assert not moved, f"value references moved: {moved}"
for i in range(5, n + 1):
    assert got[f"omega_cmd[{i}]"][0] > got["period"][0], i
print(f"ok: {kind} FMI {version}: {n} rotors, omega_cmd[1..{n}] {side}s")
PYEOF
    done
    ;;

  bad_input)
    expect_error 2 "kind: rocket not in {plant,controller}" fmu export rocket --out "$TMP/x.fmu"
    expect_error 2 "--fmi: 4 not in {2,3}" fmu export plant --fmi 4 --out "$TMP/x.fmu"
    expect_error 2 "--out: '$TMP/x.zip' must end in .fmu" fmu export plant --out "$TMP/x.zip"
    expect_error 2 "--out is required" fmu export plant
    expect_error 2 "--controller: does nothing with plant" fmu export plant --controller se3 --out "$TMP/x.fmu"
    expect_error 2 "--controller: got 'warp', expected a controller type" fmu export controller --controller warp --out "$TMP/x.fmu"
    expect_error 2 "fmu export packs one of quadcosim's controller types" fmu export controller --controller python:m:C --out "$TMP/x.fmu"
    expect_error 2 "--scenario: File does not exist: $TMP/none.yaml" fmu export plant --scenario "$TMP/none.yaml" \
      --out "$TMP/x.fmu"
    printf 'simulation:\n  plant_rate_hz: fast\n' > "$TMP/bad.yaml"
    expect_error 2 "$TMP/bad.yaml: simulation.plant_rate_hz" fmu export plant --scenario "$TMP/bad.yaml" --out "$TMP/x.fmu"
    # Unwritable: the folder of --out is a file. Nothing is left behind.
    touch "$TMP/file"
    expect_error 3 "$TMP/file/x.fmu" fmu export plant --out "$TMP/file/x.fmu"
    # An export that fails keeps an existing FMU as it was.
    "$QC" fmu export plant --out "$TMP/keep.fmu" > /dev/null
    cp "$TMP/keep.fmu" "$TMP/keep.orig"
    QUADCOSIM_FMU_LIBRARY="$TMP/no_such.so" expect_error 3 "$TMP/no_such.so" fmu export plant --fmi 3 --out "$TMP/keep.fmu"
    cmp -s "$TMP/keep.fmu" "$TMP/keep.orig" || fail "a failed export changed the existing FMU"
    ls "$TMP" | grep -q partial && fail "a partial archive was left: $(ls "$TMP")"
    # info: not an FMU.
    expect_error 2 "File does not exist: $TMP/none.fmu" fmu info "$TMP/none.fmu"
    echo "not a zip" > "$TMP/text.fmu"
    expect_error 2 "$TMP/text.fmu" fmu info "$TMP/text.fmu"
    "$PY" -c "import sys,zipfile; zipfile.ZipFile(sys.argv[1],'w').writestr('resources/x','')" "$TMP/nomd.fmu"
    expect_error 2 "$TMP/nomd.fmu: no modelDescription.xml" fmu info "$TMP/nomd.fmu"
    "$PY" -c "import sys,zipfile; zipfile.ZipFile(sys.argv[1],'w').writestr('modelDescription.xml','<fmiModelDescription fmiVersion=\"2.0\"/>')" "$TMP/badmd.fmu"
    expect_error 2 "$TMP/badmd.fmu: modelDescription.xml" fmu info "$TMP/badmd.fmu"
    expect_error 2 "A subcommand is required" fmu
    ;;

  *) fail "unknown case $CASE" ;;
esac
echo "ok: $CASE"
