#!/usr/bin/env bash
# `quadcosim margins`, one case per CTest test.
#   usage: margins_cases.sh QUADCOSIM_BINARY SOURCE_DIR CASE
source "$(dirname "${BASH_SOURCE[0]}")/../lib/cli_case.sh" "$@"
P="$SRC/scenarios/paper"

# A copy of the paper's roll scenario with one `simulation:` key set: with_simulation NAME KEY VALUE
# writes $TMP/NAME.yaml.
with_simulation() {
  "$PY" - "$P/roll_step.yaml" "$TMP/$1.yaml" "$2" "$3" <<'PYEOF'
import re, sys
text = open(sys.argv[1]).read()
key, value = sys.argv[3], sys.argv[4]
text, n = re.subn(rf"^  {key}: .*$", f"  {key}: {value}", text, flags=re.M)
if n == 0:
    text = text.replace("simulation:\n", f"simulation:\n  {key}: {value}\n", 1)
open(sys.argv[2], "w").write(text)
PYEOF
}

case "$CASE" in
  paper_closed_form)  # the paper's loops against the ZOH transfer functions of the gains `lqr` prints
    "$QC" lqr > "$TMP/lqr.txt"
    for s in altitude_step roll_step; do
      "$QC" margins "$P/$s.yaml" --json > "$TMP/$s.json" || fail "margins $s exited $?"
    done
    cmp -s "$TMP/altitude_step.json" "$TMP/roll_step.json" && fail "the JSON does not name its scenario"
    "$QC" margins "$P/roll_step.yaml" > "$TMP/table.txt"
    for loop in roll pitch yaw altitude; do grep -q "^$loop " "$TMP/table.txt" || fail "no $loop row"; done
    grep -qi nan "$TMP/table.txt" && fail "NaN in the table"
    grep -q "^note: .*rotor clamp, the tilt limit and the integral bound are not" "$TMP/table.txt" \
      || fail "no note that saturation is not in the linear loops"
    "$PY" -c "import json,sys; assert any('rotor clamp' in n for n in json.load(open(sys.argv[1]))['notes'])" \
      "$TMP/roll_step.json" || fail "margins.json notes lack saturation"
    "$PY" - "$TMP/lqr.txt" "$TMP/roll_step.json" <<'PYEOF' || fail "margins differ from the closed form"
import cmath, json, math, re, sys
lqr = open(sys.argv[1]).read()
doc = json.load(open(sys.argv[2]))
T = doc["controller_period_s"]
assert T == 0.02, T
# The gains are read as `lqr` prints them (6 significant digits): hence the tolerances below.
# x/u = T^2 (z + 1) / (2 J (z - 1)^2) and v/u = T / (J (z - 1)) for 1/(J s^2) under a ZOH; the
# controller feeds back k1 x + k2 v on the measured angle (height) and rate (speed).
plants = {}
for name, inertia, k1, k2 in re.findall(r"(\w+) axis \(I = ([\d.e-]+) kg m\^2\).*?k1 = ([\d.e-]+), k2 = ([\d.e-]+)", lqr, re.S):
    plants[name] = (float(inertia), float(k1), float(k2))
plants["altitude"] = (1.96, 4.0, 2.7)  # m, K_p,z, K_d,z (docs/controller.md defaults)
def L(w, J, k1, k2):
    z = cmath.exp(1j * w * T)
    return k1 * T * T * (z + 1) / (2 * J * (z - 1) ** 2) + k2 * T / (J * (z - 1))
for loop in doc["loops"]:
    J, k1, k2 = plants[loop["name"]]
    lo, hi = 1e-3, math.pi / T
    for _ in range(200):  # |L| falls monotonically here: bisect |L| = 1
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if abs(L(mid, J, k1, k2)) > 1 else (lo, mid)
    wgc = lo
    pm = math.degrees(cmath.phase(L(wgc, J, k1, k2))) + 180.0
    gm_db = -20 * math.log10(abs(L(math.pi / T, J, k1, k2)))  # phase -180 at Nyquist
    got = loop["phase_margin"]
    assert abs(got["frequency_rad_s"] - wgc) < 2e-5 * wgc, (loop["name"], got, wgc)
    assert abs(got["deg"] - pm) < 2e-3, (loop["name"], got, pm)
    assert abs(loop["gain_margin"]["db"] - gm_db) < 1e-3, (loop["name"], loop["gain_margin"], gm_db)
    assert abs(loop["delay_margin"]["s"] - math.radians(pm) / wgc) < 2e-5 * loop["delay_margin"]["s"], loop["name"]
    assert loop["gain_reduction_margin"]["status"] == "infinite"
    print(f"{loop['name']}: PM {pm:.3f} deg at {wgc:.4f} rad/s, GM {gm_db:.3f} dB: as the closed form")
PYEOF
    ;;

  delay_and_rate)  # one sample of command delay costs w_gc T of phase; a slower controller loses phase
    "$QC" margins "$P/roll_step.yaml" --json > "$TMP/base.json"
    with_simulation delay command_delay_ticks 2
    "$QC" margins "$TMP/delay.yaml" --json > "$TMP/delay.json"
    with_simulation slow controller_rate_hz 25
    "$QC" margins "$TMP/slow.yaml" --json > "$TMP/slow.json"
    "$PY" - "$TMP/base.json" "$TMP/delay.json" "$TMP/slow.json" <<'PYEOF' || fail "margins did not move as expected"
import json, math, sys
base, delay, slow = (json.load(open(p)) for p in sys.argv[1:4])
assert delay["command_delay_ticks"] == 2 and slow["controller_period_s"] == 0.04
for b, d, s in zip(base["loops"], delay["loops"], slow["loops"]):
    w = b["phase_margin"]["frequency_rad_s"]
    assert abs(d["phase_margin"]["frequency_rad_s"] - w) < 1e-6 * w, b["name"]
    drop = b["phase_margin"]["deg"] - d["phase_margin"]["deg"]
    assert abs(drop - math.degrees(w * 0.02)) < 1e-5, (b["name"], drop, math.degrees(w * 0.02))
    assert abs(b["delay_margin"]["s"] - d["delay_margin"]["s"] - 0.02) < 1e-8, b["name"]
    assert s["phase_margin"]["deg"] < b["phase_margin"]["deg"], b["name"]
    assert s["gain_margin"]["db"] < b["gain_margin"]["db"], b["name"]
    print(f"{b['name']}: PM {b['phase_margin']['deg']:.2f} -> {d['phase_margin']['deg']:.2f} deg with one "
          f"sample of delay, {s['phase_margin']['deg']:.2f} deg at 25 Hz")
PYEOF
    ;;

  out_and_plots)  # --out writes the JSON, the table, the response and a Bode and Nyquist PNG per loop
    "$QC" margins "$SRC/scenarios/examples/position_step.yaml" --out "$TMP/m" > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "exit $?"; }
    for loop in roll pitch yaw altitude position_x position_y; do
      for kind in bode nyquist; do
        [ -s "$TMP/m/${kind}_$loop.png" ] || fail "no ${kind}_$loop.png"
      done
      grep -q "^$loop," "$TMP/m/frequency_response.csv" || fail "no response rows for $loop"
    done
    "$PY" -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['mode']=='position' and len(d['loops'])==6" "$TMP/m/margins.json" \
      || fail "margins.json lacks the position loops"
    cmp <(sed -n '1,20p' "$TMP/m/margins.txt") <(sed -n '1,20p' "$TMP/log" | grep -v '\.png$') || fail "margins.txt is not the table printed"
    "$QC" margins --out "$TMP/np" --no-plots > /dev/null || fail "--no-plots failed"
    ls "$TMP/np"/*.png > /dev/null 2>&1 && fail "--no-plots wrote PNGs"
    [ -s "$TMP/np/margins.json" ] || fail "no margins.json with --no-plots"
    # Again into the same folder: refused; with --force, in attitude mode, the position plots of the
    # first analysis go.
    set +e
    "$QC" margins "$P/roll_step.yaml" --out "$TMP/m" > /dev/null 2> "$TMP/err"; rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q "$TMP/m is not empty: it holds the outputs of \`quadcosim margins\`" "$TMP/err" \
      || fail "re-using a margins folder without --force: exit $rc: $(cat "$TMP/err")"
    "$QC" margins "$P/roll_step.yaml" --out "$TMP/m" --force > /dev/null || fail "re-using a margins folder failed"
    [ -e "$TMP/m/bode_position_x.png" ] && fail "a stale position_x plot survived"
    [ -s "$TMP/m/bode_roll.png" ] || fail "no bode_roll.png the second time"
    # A folder with someone else's files is refused, and left as it was.
    mkdir "$TMP/run" && echo t > "$TMP/run/trajectory.csv"
    set +e
    "$QC" margins --out "$TMP/run" > /dev/null 2> "$TMP/err"; rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q "trajectory.csv" "$TMP/err" || fail "foreign folder: exit $rc: $(cat "$TMP/err")"
    [ "$(ls "$TMP/run")" = trajectory.csv ] || fail "the foreign folder was changed"
    ;;

  unstable)  # a loop the delay destabilises: exit 1, margins stated undefined, no NaN anywhere
    with_simulation late command_delay_ticks 40
    set +e
    "$QC" margins "$TMP/late.yaml" > "$TMP/table.txt" 2>&1; rc=$?
    "$QC" margins "$TMP/late.yaml" --json > "$TMP/late.json" 2>/dev/null
    set -e
    [ "$rc" = 1 ] || { cat "$TMP/table.txt"; fail "exit $rc, expected 1"; }
    grep -q "^roll .*undefined.*UNSTABLE" "$TMP/table.txt" || { cat "$TMP/table.txt"; fail "roll not reported unstable"; }
    grep -qi nan "$TMP/table.txt" "$TMP/late.json" && fail "NaN printed"
    "$PY" - "$TMP/late.json" <<'PYEOF' || fail "JSON does not state the undefined margins"
import json, sys
d = json.load(open(sys.argv[1]))
roll = d["loops"][0]
assert roll["closed_loop_stable"] is False
for k in ("gain_margin", "phase_margin", "delay_margin"):
    assert roll[k]["status"] == "undefined" and roll[k][{"gain_margin": "db", "phase_margin": "deg", "delay_margin": "s"}[k]] is None, k
PYEOF
    ;;

  bad_input)  # a vehicle that cannot hover, a bad file, a flag without its partner: exit 2, named
    sed 's/^simulation:/vehicle:\n  motor: {omega_max_rad_s: 4000}\nsimulation:/' "$P/roll_step.yaml" > "$TMP/weak.yaml"
    set +e
    "$QC" margins "$TMP/weak.yaml" > "$TMP/out" 2> "$TMP/err"; rc=$?
    set -e
    [ "$rc" = 2 ] || { cat "$TMP/out" "$TMP/err"; fail "weak motors: exit $rc, expected 2"; }
    grep -q "cannot hover" "$TMP/err" && grep -q "omega_max" "$TMP/err" || { cat "$TMP/err"; fail "message does not say why"; }
    printf 'name: [\n' > "$TMP/broken.yaml"
    set +e
    "$QC" margins "$TMP/broken.yaml" > /dev/null 2> "$TMP/err2"; rc=$?
    "$QC" margins --no-plots > /dev/null 2> "$TMP/err3"; rc3=$?
    "$QC" margins "$TMP/missing.yaml" > /dev/null 2>&1; rc4=$?
    set -e
    [ "$rc" = 2 ] && grep -q "broken.yaml" "$TMP/err2" || fail "broken YAML: exit $rc: $(cat "$TMP/err2")"
    [ "$rc3" = 2 ] && grep -q -- "--no-plots needs --out" "$TMP/err3" || fail "--no-plots alone: exit $rc3"
    [ "$rc4" = 2 ] || fail "missing file: exit $rc4"
    # A bad scenario is refused before --out is touched: --force removes no previous outputs for it.
    "$QC" margins --out "$TMP/prev" --no-plots > /dev/null || fail "margins --out failed"
    ls -l --time-style=full-iso "$TMP/prev" > "$TMP/prev.before"
    sed 's/^schedule:/schedule:\n  - at_s: 1\n    set: {altitude.kp: -4.0}/' "$P/roll_step.yaml" > "$TMP/refused.yaml"
    grep -q "altitude.kp: -4.0" "$TMP/refused.yaml" || fail "the refused-schedule scenario was not made"
    for bad in weak broken refused; do
      set +e
      "$QC" margins "$TMP/$bad.yaml" --out "$TMP/prev" --force > /dev/null 2> "$TMP/err"; rc=$?
      set -e
      [ "$rc" = 2 ] && grep -q "$bad.yaml" "$TMP/err" \
        || fail "$bad.yaml with --out --force: exit $rc: $(cat "$TMP/err")"
      ls -l --time-style=full-iso "$TMP/prev" | cmp -s - "$TMP/prev.before" || fail "$bad.yaml: --out changed"
    done
    grep -q "altitude.kp" "$TMP/err" || fail "the refused change is not named: $(cat "$TMP/err")"
    ;;

  measured_any_controller)  # se3 and example_pd measured: finite margins, the table, the files, a Bode PNG
    "$QC" margins "$P/roll_step.yaml" --controller se3 --out "$TMP/se3" > "$TMP/se3.log" 2>&1 \
      || { cat "$TMP/se3.log"; fail "margins --controller se3 exited $?"; }
    grep -q "^measured margins of .*controller se3" "$TMP/se3/margins.txt" || fail "no measured heading"
    for loop in roll pitch yaw altitude; do
      grep -q "^$loop .*in hover" "$TMP/se3/margins.txt" || fail "no measured $loop row"
      grep -q "^$loop," "$TMP/se3/measured_response.csv" || fail "no measured response rows for $loop"
      [ -s "$TMP/se3/bode_$loop.png" ] && [ -s "$TMP/se3/nyquist_$loop.png" ] || fail "no plots for $loop"
    done
    [ -e "$TMP/se3/frequency_response.csv" ] && fail "an analytic response for a controller without one"
    grep -qi nan "$TMP/se3/margins.txt" && fail "NaN in the table"
    "$QC" margins --controller example_pd --json > "$TMP/pd.json" 2> /dev/null || fail "example_pd exited $?"
    "$PY" - "$TMP/se3/margins.json" "$TMP/pd.json" <<'PYEOF' || fail "measured margins not finite"
import json, math, sys
for path in sys.argv[1:]:
    doc = json.load(open(path))
    assert "loops" not in doc, "analytic loops for a controller without them"
    m = doc["measured"]
    assert len(m["loops"]) == 4, m["loops"]
    for loop in m["loops"]:
        assert loop["stayed_in_hover"] and loop["unconverged_points"] == 0, loop["name"]
        pm, gm = loop["phase_margin"], loop["gain_margin"]
        assert pm["status"] == "finite" and 0 < pm["deg"] < 180, (loop["name"], pm)
        assert gm["status"] == "finite" and gm["db"] > 0, (loop["name"], gm)
        assert math.isclose(loop["delay_margin"]["s"], math.radians(pm["deg"]) / pm["frequency_rad_s"], rel_tol=1e-9)
        print(f"{m['controller']} {loop['name']}: PM {pm['deg']:.1f} deg at {pm['frequency_rad_s']:.3g} rad/s, GM {gm['db']:.1f} dB")
PYEOF
    ;;

  measured_paper_and_delay)  # --measure: the paper's measured margins beside its analytic ones; delay costs w tau
    "$QC" margins "$P/roll_step.yaml" --measure --json > "$TMP/both.json" 2> /dev/null || fail "--measure exited $?"
    with_simulation delay command_delay_ticks 2
    "$QC" margins "$TMP/delay.yaml" --controller se3 --json > "$TMP/se3_delay.json" 2> /dev/null || fail "se3 delay exited $?"
    "$QC" margins "$P/roll_step.yaml" --controller se3 --json > "$TMP/se3.json" 2> /dev/null || fail "se3 exited $?"
    "$PY" - "$TMP/both.json" "$TMP/se3.json" "$TMP/se3_delay.json" <<'PYEOF' || fail "measured margins off"
import json, math, sys
both, se3, late = (json.load(open(p)) for p in sys.argv[1:4])
for a, m in zip(both["loops"], both["measured"]["loops"]):
    assert a["name"] == m["name"]
    assert abs(a["phase_margin"]["deg"] - m["phase_margin"]["deg"]) < 0.05, (a["name"], a["phase_margin"], m["phase_margin"])
    assert abs(a["gain_margin"]["db"] - m["gain_margin"]["db"]) < 0.02, (a["name"], a["gain_margin"], m["gain_margin"])
    print(f"paper {a['name']}: PM analytic {a['phase_margin']['deg']:.3f}, measured {m['phase_margin']['deg']:.3f} deg")
assert late["measured"]["command_delay_ticks"] == 2
for b, d in zip(se3["measured"]["loops"], late["measured"]["loops"]):
    w = b["phase_margin"]["frequency_rad_s"]
    drop = b["phase_margin"]["deg"] - d["phase_margin"]["deg"]
    assert abs(drop - math.degrees(w * 0.02)) < 0.05, (b["name"], drop, math.degrees(w * 0.02))
    print(f"se3 {b['name']}: one sample of delay costs {drop:.3f} deg, w tau = {math.degrees(w * 0.02):.3f} deg")
PYEOF
    # The analytic-only flags are refused without --measure for the paper controller.
    set +e
    "$QC" margins "$P/roll_step.yaml" --amplitude 1e-3 > /dev/null 2> "$TMP/err"; rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q -- "--measure" "$TMP/err" || fail "--amplitude without --measure: exit $rc"
    ;;

  measured_python)  # a controller written in Python against the closed form of its own PD law
    cat > "$TMP/level_pd.py" <<'PYEOF'
import math

import quadcosim


class LevelPD(quadcosim.Controller):
    def __init__(self, vehicle):
        super().__init__(vehicle)
        self.m, self.g = vehicle["mass_kg"], vehicle["gravity_m_s2"]
        self.J = (vehicle["Ixx_kg_m2"], vehicle["Iyy_kg_m2"], vehicle["Izz_kg_m2"])
        self.M = vehicle["mixer_inverse"]

    def step(self, obs, ref, dt):
        a_z = 1.0 * float(ref.p[2] - obs.p[2]) - 1.4 * float(obs.v[2])
        errors = (ref.roll - obs.roll, ref.pitch - obs.pitch, math.remainder(ref.yaw - obs.yaw, 2 * math.pi))
        U = [self.m * (self.g + a_z)] + [J * (64.0 * e - 12.0 * w) for J, e, w in zip(self.J, errors, obs.w)]
        return [math.sqrt(max(sum(m * u for m, u in zip(row, U)), 0.0)) for row in self.M]
PYEOF
    printf 'simulation: {plant_rate_hz: 100, controller_rate_hz: 50}\ncontroller: {python: "level_pd:LevelPD", mode: attitude, z_des: 10}\n' > "$TMP/py.yaml"
    set +e
    "$QC" margins "$TMP/py.yaml" --json > "$TMP/py.json" 2> "$TMP/err"; rc=$?
    set -e
    if grep -q "without Python" "$TMP/err"; then echo "SKIP: this quadcosim was built without Python"; exit 77; fi
    [ "$rc" = 0 ] || { cat "$TMP/err"; fail "Python controller: exit $rc"; }
    "$PY" - "$TMP/py.json" <<'PYEOF' || fail "the Python controller's measured margins differ from the closed form"
import cmath, json, math, sys
doc = json.load(open(sys.argv[1]))["measured"]
assert doc["controller"] == "python", doc["controller"]
T = doc["controller_period_s"]
# U = J (kp e - kd w) on a 1/(J s^2) axis sampled with a ZOH: L = kp T^2 (z+1) / (2 (z-1)^2) + kd T / (z-1),
# the inertia cancelling; altitude alike with kp 1.0, kd 1.4 (the mass cancels).
gains = {"roll": (64.0, 12.0), "pitch": (64.0, 12.0), "yaw": (64.0, 12.0), "altitude": (1.0, 1.4)}
for loop in doc["loops"]:
    kp, kd = gains[loop["name"]]
    L = lambda w: (lambda z: kp * T * T * (z + 1) / (2 * (z - 1) ** 2) + kd * T / (z - 1))(cmath.exp(1j * w * T))
    lo, hi = 1e-3, math.pi / T
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if abs(L(mid)) > 1 else (lo, mid)
    pm = math.degrees(cmath.phase(L(lo))) + 180.0
    gm_db = -20 * math.log10(abs(L(math.pi / T)))
    got = loop["phase_margin"]
    assert abs(got["deg"] - pm) < 0.05 and abs(got["frequency_rad_s"] / lo - 1) < 1e-3, (loop["name"], got, pm, lo)
    assert abs(loop["gain_margin"]["db"] - gm_db) < 0.02, (loop["name"], loop["gain_margin"], gm_db)
    print(f"python {loop['name']}: PM {got['deg']:.3f} deg (closed form {pm:.3f}) at {lo:.4f} rad/s, GM {gm_db:.3f} dB")
PYEOF
    ;;

  measured_fmu)  # the paper controller exported as an FMU, measured: its analytic margins
    "$QC" fmu export --help > /dev/null 2>&1 || { echo "SKIP: this build has no 'quadcosim fmu export'"; exit 77; }
    "$QC" fmu export controller --scenario "$P/roll_step.yaml" --out "$TMP/controller.fmu" > /dev/null 2>&1 \
      || fail "fmu export controller failed"
    sed 's/^controller:$/controller:\n  fmu: controller.fmu/' "$P/roll_step.yaml" > "$TMP/fmu.yaml"
    grep -q 'fmu: controller.fmu' "$TMP/fmu.yaml" || fail "could not write the scenario"
    "$QC" margins "$TMP/fmu.yaml" --json > "$TMP/fmu.json" 2> "$TMP/err" || { cat "$TMP/err"; fail "FMU controller: exit $?"; }
    "$QC" margins "$P/roll_step.yaml" --json > "$TMP/paper.json"
    "$PY" - "$TMP/paper.json" "$TMP/fmu.json" <<'PYEOF' || fail "the FMU controller's measured margins differ from the analytic ones"
import json, sys
paper, fmu = (json.load(open(p)) for p in sys.argv[1:3])
assert fmu["measured"]["controller"] == "fmu", fmu["measured"]["controller"]
for a, m in zip(paper["loops"], fmu["measured"]["loops"]):
    assert abs(a["phase_margin"]["deg"] - m["phase_margin"]["deg"]) < 0.05, (a["name"], a["phase_margin"], m["phase_margin"])
    assert abs(a["gain_margin"]["db"] - m["gain_margin"]["db"]) < 0.02, (a["name"], a["gain_margin"], m["gain_margin"])
    print(f"FMU {a['name']}: PM {m['phase_margin']['deg']:.3f} deg (analytic {a['phase_margin']['deg']:.3f}), GM {m['gain_margin']['db']:.3f} dB")
PYEOF
    ;;

  measured_unstable)  # a measured loop the delay destabilises: exit 1, LEFT HOVER, undefined, no NaN
    with_simulation late command_delay_ticks 40
    set +e
    "$QC" margins "$TMP/late.yaml" --controller example_pd --frequencies 6 > "$TMP/table.txt" 2>&1; rc=$?
    set -e
    [ "$rc" = 1 ] || { cat "$TMP/table.txt"; fail "exit $rc, expected 1"; }
    grep -q "^roll .*undefined.*LEFT HOVER" "$TMP/table.txt" || { cat "$TMP/table.txt"; fail "roll not reported as leaving hover"; }
    grep -qi nan "$TMP/table.txt" && fail "NaN printed"
    ;;

  lqr_and_bench_other_controllers)  # lqr names what to use instead; bench --scenario flies any controller
    printf 'type: se3\n' > "$TMP/se3.yaml"
    set +e
    "$QC" lqr --params "$TMP/se3.yaml" > /dev/null 2> "$TMP/err"; rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q "controller type 'se3'" "$TMP/err" && grep -q "quadcosim margins SCENARIO --controller se3" "$TMP/err" \
      || fail "lqr on se3: exit $rc: $(cat "$TMP/err")"
    "$QC" bench --quick --only inproc --json --scenario "$SRC/scenarios/tracking/circle_se3.yaml" > "$TMP/bench.json" 2> "$TMP/bench.err" \
      || { cat "$TMP/bench.err"; fail "bench --scenario circle_se3 exited $?"; }
    "$PY" -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['inproc_rtf']>0 and d['baseline_rtf'] is None and d['inproc_vs_baseline'] is None, d" \
      "$TMP/bench.json" || fail "bench with se3: $(cat "$TMP/bench.json")"
    grep -q "baseline_rtf skipped" "$TMP/bench.err" || fail "bench does not say why the baseline is skipped"
    ;;

  *) fail "unknown case" ;;
esac
echo "ok [$CASE]"
