#!/usr/bin/python3
"""Tests for tools/plot_run.py.

Run:  /usr/bin/python3 tools/test_plot_run.py   (stdlib unittest; numpy needed
for the synthetic data; plot_run.py itself is run as a subprocess with an
interpreter that has matplotlib).

The helpers make_run()/second_order() are also handy to produce a synthetic
run directory by hand:
    /usr/bin/python3 -c 'import sys; sys.path.insert(0, "tools"); \
        import test_plot_run as t; t.make_run("/tmp/run", steps=[("z", 0, 0, 10)])'
"""

import importlib.util
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "plot_run.py")

COLUMNS = ["t", "x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz",
           "roll", "pitch", "yaw", "p", "q", "r", "w1", "w2", "w3", "w4",
           "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des"]
RATE = {"x": "vx", "y": "vy", "z": "vz", "roll": "p", "pitch": "q", "yaw": "r"}
# (zeta, wn) per channel, roughly the paper's responses
DYNAMICS = {"x": (0.7, 1.0), "y": (0.7, 1.0), "z": (0.479, 1.43),
            "roll": (1.0, 1.2), "pitch": (1.0, 1.25), "yaw": (1.0, 0.6)}
REFERENCE = {
    "z": {"source": "paper Fig. 4", "overshoot_pct": 18.0, "peak_time_s": 2.5,
          "settling_time_2pct_s": 8.0},
    "roll": {"source": "paper Fig. 5", "overshoot_pct": 0.0, "t95_s": 4.0,
             "settling_time_2pct_s": 6.0},
    "pitch": {"source": "paper Fig. 6", "overshoot_pct": 0.0},
    "yaw": {"source": "paper Fig. 7", "overshoot_pct": 0.0, "settling_time_2pct_s": 8.0},
}


def plot_python():
    """An interpreter that can import matplotlib (the pyenv python in PATH cannot)."""
    if importlib.util.find_spec("matplotlib") is not None:
        return sys.executable
    return "/usr/bin/python3"


def second_order(t, zeta, wn):
    """Unit step response s(t) and its derivative, s = 0 for t < 0."""
    tt = np.maximum(t, 0.0)
    if zeta < 1.0:
        wd = wn * math.sqrt(1.0 - zeta ** 2)
        phi = math.acos(zeta)
        e = np.exp(-zeta * wn * tt)
        s = 1.0 - e / math.sqrt(1.0 - zeta ** 2) * np.sin(wd * tt + phi)
        ds = wn / math.sqrt(1.0 - zeta ** 2) * e * np.sin(wd * tt)
    else:  # critically damped
        e = np.exp(-wn * tt)
        s = 1.0 - (1.0 + wn * tt) * e
        ds = wn ** 2 * tt * e
    s[t < 0] = 0.0
    ds[t < 0] = 0.0
    return s, ds


def step_figures(t, y, t_step, initial, target):
    """Classic step figures, measured from t_step (what plot_run.py assumes)."""
    m = t >= t_step
    tr, yr = t[m] - t_step, y[m]
    span = target - initial
    e = (yr - initial) / span  # normalised response
    k = int(np.argmax(e))
    over = float(max(0.0, (e[k] - 1.0) * 100.0))
    peak = float(tr[k]) if e[k] > 1.0 else None

    def first(cond):
        idx = np.nonzero(cond)[0]
        return float(tr[idx[0]]) if idx.size else None

    r10, r90 = first(e >= 0.1), first(e >= 0.9)
    outside = np.nonzero(np.abs(e - 1.0) > 0.02)[0]
    settle = float(tr[outside[-1] + 1]) if outside.size and outside[-1] + 1 < len(tr) else (
        0.0 if not outside.size else None)
    return {"overshoot_pct": round(over, 2), "peak_time_s": peak,
            "rise_time_s": None if r10 is None or r90 is None else round(r90 - r10, 3),
            "t95_s": first(e >= 0.95), "settling_time_2pct_s": settle,
            "steady_state_error_pct": round(float(abs(1.0 - e[-1])) * 100.0, 3)}


def make_run(run_dir, steps, n_rows=1501, dt=0.01, with_metrics=True, drop=(),
             extra_columns=True, scenario="synthetic"):
    """Writes run_dir/trajectory.csv (+ metrics.json). steps: (channel, t_step, initial, target)."""
    os.makedirs(run_dir, exist_ok=True)
    t = np.arange(n_rows) * dt
    cols = {c: np.zeros(n_rows) for c in COLUMNS}
    cols["t"] = t
    for ch, t_step, initial, target in steps:
        zeta, wn = DYNAMICS[ch]
        s, ds = second_order(t - t_step, zeta, wn)
        cols[ch] = initial + (target - initial) * s
        cols[RATE[ch]] = (target - initial) * ds
        cols[f"{ch}_des"] = np.where(t >= t_step, target, initial)
    # a little sensor-like noise on the off-axis channels
    rng = np.random.default_rng(1)
    stepped = {s[0] for s in steps}
    for ch in ("x", "y", "roll", "pitch", "yaw"):
        if ch not in stepped:
            cols[ch] = 1e-4 * rng.standard_normal(n_rows).cumsum() / math.sqrt(n_rows)
    cr, sr = np.cos(cols["roll"] / 2), np.sin(cols["roll"] / 2)
    cp, sp = np.cos(cols["pitch"] / 2), np.sin(cols["pitch"] / 2)
    cy, sy = np.cos(cols["yaw"] / 2), np.sin(cols["yaw"] / 2)
    cols["qw"] = cr * cp * cy + sr * sp * sy
    cols["qx"] = sr * cp * cy - cr * sp * sy
    cols["qy"] = cr * sp * cy + sr * cp * sy
    cols["qz"] = cr * cp * sy - sr * sp * cy
    hover = math.sqrt(1.96 * 9.81 / (4 * 2.06e-7))
    az = np.gradient(cols["vz"], dt)
    for i, c in enumerate(("w1", "w2", "w3", "w4")):
        sign = (-1) ** i
        cols[c] = hover * np.sqrt(np.maximum(0.05, 1.0 + az / 9.81)) + 40 * sign * cols["r"] \
            + 25 * sign * (cols["p"] - cols["q"])

    names = [c for c in COLUMNS if c not in drop]
    data = [cols[c] for c in names]
    if extra_columns:  # unknown columns in the middle and at the end, must be ignored
        names.insert(11, "thrust_cmd")
        data.insert(11, 4 * 2.06e-7 * cols["w1"] ** 2)
    with open(os.path.join(run_dir, "trajectory.csv"), "w") as f:
        f.write(",".join(names) + (",safety" if extra_columns else "") + "\n")
        arr = np.column_stack(data)
        flags = np.where(np.arange(n_rows) % 7 == 0, "clamped", "ok")
        for i, row in enumerate(arr):
            f.write(",".join(repr(float(v)) for v in row)
                    + (f",{flags[i]}" if extra_columns else "") + "\n")

    if with_metrics:
        entries = []
        for ch, t_step, initial, target in steps:
            figs = step_figures(t, cols[ch], t_step, initial, target)
            crit = [{"figure": "overshoot_pct", "min": 15, "max": 21,
                     "value": figs["overshoot_pct"], "passed": 15 <= figs["overshoot_pct"] <= 21}] \
                if ch == "z" else [{"figure": "overshoot_pct", "max": 2.0,
                                    "value": figs["overshoot_pct"],
                                    "passed": figs["overshoot_pct"] <= 2.0}]
            if figs["settling_time_2pct_s"] is not None:
                crit.append({"figure": "settling_time_2pct_s", "max": 10.0,
                             "value": figs["settling_time_2pct_s"],
                             "passed": figs["settling_time_2pct_s"] <= 10.0})
            entry = {"channel": ch, "t_step_s": t_step, "initial": initial, "target": target,
                     "figures": figs, "criteria": crit,
                     "passed": all(c["passed"] for c in crit)}
            if ch in REFERENCE:
                entry["reference"] = REFERENCE[ch]
            entries.append(entry)
        with open(os.path.join(run_dir, "metrics.json"), "w") as f:
            json.dump({"scenario": scenario, "description": "synthetic second-order responses",
                       "steps": entries, "passed": all(e["passed"] for e in entries)}, f, indent=2)


def make_tracking_run(run_dir, tracking=True, psi=True, n_rows=2001, dt=0.01, offset_x=0.03):
    """A run tracking a 2 m circle at 5 m (10 s a lap): the reference held between 50 Hz controller
    steps, the vehicle `offset_x` behind it in x; att_err a constant 1e-4 (nan when not psi).
    metrics.json has "tracking" when `tracking` (after_s 5, reference_period_s 0.02)."""
    make_run(run_dir, [], n_rows=n_rows, dt=dt, with_metrics=False, extra_columns=False)
    t = np.arange(n_rows) * dt
    held = t - np.remainder(np.round(t / dt).astype(int), 2) * dt  # the last controller step's time
    ang, ang_held = 2 * math.pi * t / 10.0, 2 * math.pi * held / 10.0
    with open(os.path.join(run_dir, "trajectory.csv")) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(os.path.join(run_dir, "trajectory.csv"), delimiter=",", skiprows=1, ndmin=2)
    col = {n: data[:, i] for i, n in enumerate(names)}
    col["x"], col["y"], col["z"] = 2 * np.cos(ang) - offset_x, 2 * np.sin(ang), np.full(n_rows, 5.0)
    col["x_des"], col["y_des"], col["z_des"] = 2 * np.cos(ang_held), 2 * np.sin(ang_held), np.full(n_rows, 5.0)
    names = names + ["att_err"]
    col["att_err"] = np.full(n_rows, 1e-4 if psi else math.nan)
    with open(os.path.join(run_dir, "trajectory.csv"), "w") as f:
        f.write(",".join(names) + "\n")
        for row in np.column_stack([col[n] for n in names]):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    metrics = {"scenario": "circle", "description": "synthetic circle", "steps": [], "passed": True}
    if tracking:
        metrics["tracking"] = {
            "after_s": 5.0, "reference_period_s": 0.02, "samples": 751,
            "figures": {"position_rmse_m": offset_x, "position_max_m": offset_x, "x_rmse_m": offset_x,
                        "yaw_rmse_rad": 0.0, "attitude_error_rmse": 1e-4 if psi else None},
            "criteria": [{"figure": "position_rmse_m", "min": None, "max": 0.05, "value": offset_x,
                          "passed": True, "note": None}],
            "passed": True}
    with open(os.path.join(run_dir, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)


def png_size(path):
    """(width, height) from the IHDR chunk; raises AssertionError if not a PNG."""
    with open(path, "rb") as f:
        head = f.read(33)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: bad PNG signature"
    length, ctype = struct.unpack(">I4s", head[8:16])
    assert ctype == b"IHDR" and length == 13, f"{path}: first chunk is not IHDR"
    return struct.unpack(">II", head[16:24])


class PlotRunTest(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="plot_run_test_")
        self.tmp = self._tmp.name

    def tearDown(self):
        self._tmp.cleanup()

    def run_script(self, run_dir, timeout=120):
        env = dict(os.environ, MPLCONFIGDIR=os.path.join(self.tmp, "mplconfig"))
        return subprocess.run([plot_python(), SCRIPT, run_dir], capture_output=True, text=True,
                              timeout=timeout, env=env)

    def assert_png(self, path, min_wh, max_wh):
        self.assertTrue(os.path.isfile(path), f"{path} not written")
        w, h = png_size(path)
        self.assertTrue(min_wh[0] <= w <= max_wh[0] and min_wh[1] <= h <= max_wh[1],
                        f"{path}: implausible size {w}x{h}")
        self.assertGreater(os.path.getsize(path), 10_000, f"{path}: suspiciously small")

    def assert_step_png(self, path):  # 8x5 in at 150 dpi = 1200x750
        self.assert_png(path, (900, 560), (1600, 1000))

    def assert_overview_png(self, path):  # 15x9 in at 150 dpi
        self.assert_png(path, (1500, 900), (3000, 2000))

    def test_with_metrics(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0)])
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        for name in ("step_z.png", "overview.png"):
            self.assertIn(os.path.join(run, name), res.stdout.splitlines())
        self.assert_step_png(os.path.join(run, "step_z.png"))
        self.assert_overview_png(os.path.join(run, "overview.png"))
        self.assertFalse(os.path.exists(os.path.join(run, "step_roll.png")))

    def test_without_metrics_detects_changed_setpoints(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("roll", 1.0, 0.0, 0.1), ("yaw", 0.5, 0.0, 0.2)], with_metrics=False)
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        for name in ("step_roll.png", "step_yaw.png"):
            self.assert_step_png(os.path.join(run, name))
        self.assert_overview_png(os.path.join(run, "overview.png"))
        for name in ("step_z.png", "step_pitch.png", "step_x.png"):
            self.assertFalse(os.path.exists(os.path.join(run, name)), name)

    def test_null_figures_and_repeated_channel(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("pitch", 0.0, 0.0, 0.15)])
        with open(os.path.join(run, "metrics.json")) as f:
            m = json.load(f)
        m["steps"][0]["figures"]["peak_time_s"] = None
        m["steps"][0]["figures"]["settling_time_2pct_s"] = None
        m["steps"].append(dict(m["steps"][0], t_step_s=10.0, initial=0.15, target=0.0))
        with open(os.path.join(run, "metrics.json"), "w") as f:
            json.dump(m, f)
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assert_step_png(os.path.join(run, "step_pitch.png"))
        self.assert_step_png(os.path.join(run, "step_pitch_2.png"))

    def test_missing_column_is_an_error(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0)], n_rows=200, drop=("z",))
        res = self.run_script(run)
        self.assertNotEqual(res.returncode, 0)
        self.assertIn("trajectory.csv", res.stderr)
        self.assertIn("'z'", res.stderr)
        self.assertFalse(os.path.exists(os.path.join(run, "overview.png")))

    def test_missing_trajectory_is_an_error(self):
        run = os.path.join(self.tmp, "empty")
        os.makedirs(run)
        res = self.run_script(run)
        self.assertNotEqual(res.returncode, 0)
        self.assertIn("trajectory.csv", res.stderr)

    def test_malformed_row_is_an_error(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0)], n_rows=50, with_metrics=False,
                 extra_columns=False)
        with open(os.path.join(run, "trajectory.csv"), "a") as f:
            f.write("0.5,1,2\n")
        res = self.run_script(run)
        self.assertNotEqual(res.returncode, 0)
        self.assertIn("trajectory.csv", res.stderr)
        self.assertIn("line 52", res.stderr)

    def test_malformed_metrics_is_an_error(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0)], n_rows=200)
        with open(os.path.join(run, "metrics.json"), "w") as f:
            f.write('{"steps": [ {"channel": "z", ')
        res = self.run_script(run)
        self.assertNotEqual(res.returncode, 0)
        self.assertIn("metrics.json", res.stderr)
        with open(os.path.join(run, "metrics.json"), "w") as f:
            json.dump({"steps": [{"channel": "altitude", "t_step_s": 0, "initial": 0,
                                  "target": 1}]}, f)
        res = self.run_script(run)
        self.assertNotEqual(res.returncode, 0)
        self.assertIn("metrics.json", res.stderr)
        self.assertIn("channel", res.stderr)

    def test_long_file(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0), ("yaw", 300.0, 0.0, 0.2)], n_rows=100_000,
                 with_metrics=False)
        start = time.monotonic()
        res = self.run_script(run, timeout=300)
        elapsed = time.monotonic() - start
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assert_step_png(os.path.join(run, "step_z.png"))
        self.assert_step_png(os.path.join(run, "step_yaw.png"))
        self.assert_overview_png(os.path.join(run, "overview.png"))
        self.assertLess(elapsed, 120.0)


class UnwrapAndSaturationTest(unittest.TestCase):
    """The helpers behind unwrapped angle plots and saturation shading, against hand counts."""

    @classmethod
    def setUpClass(cls):
        if importlib.util.find_spec("matplotlib") is None:
            raise unittest.SkipTest("matplotlib not importable in this interpreter")
        spec = importlib.util.spec_from_file_location("plot_run", SCRIPT)
        cls.pr = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(cls.pr)

    def test_unwrap_takes_the_short_way_and_keeps_nan(self):
        # Yaw 3.0 -> 3.283 rad as recorded: wraps to about -3.0 past pi.
        true = 3.0 + (2 * math.pi - 6.0) * (1 - np.exp(-np.arange(0, 5, 0.01) / 0.3))
        rec = np.remainder(true + math.pi, 2 * math.pi) - math.pi
        self.assertLess(rec.min(), -2.9)  # the record does wrap
        np.testing.assert_allclose(self.pr.unwrap_angle(rec), true, atol=1e-12)
        with_nan = np.array([math.nan, 3.1, -3.1, math.nan, -3.0])
        u = self.pr.unwrap_angle(with_nan)
        self.assertTrue(math.isnan(u[0]) and math.isnan(u[3]))
        self.assertAlmostEqual(u[2], -3.1 + 2 * math.pi, places=12)
        self.assertAlmostEqual(u[4], -3.0 + 2 * math.pi, places=12)

    def test_step_title_gives_the_commanded_step_and_the_shortest_path(self):
        # Yaw 3.0 -> -3.0 rad as commanded; flown the short way: +(2 pi - 6) = +0.2832 rad, to 3.283.
        yaw = {"channel": "yaw", "initial": 3.0, "target": -3.0, "step": 2 * math.pi - 6.0}
        self.assertEqual(self.pr.step_title(yaw), "Yaw step 3 → −3 rad (shortest path +0.2832 rad, to 3.283)")
        # Target more than pi away the other way: 0 -> 4 rad is the -2.283 rad turn.
        far = {"channel": "roll", "initial": 0.0, "target": 4.0, "step": 4.0 - 2 * math.pi}
        self.assertEqual(self.pr.step_title(far), "Roll step 0 → 4 rad (shortest path −2.283 rad, to −2.283)")
        # The short way already: nothing added; a position step is never an angle.
        self.assertEqual(self.pr.step_title({"channel": "yaw", "initial": 0.0, "target": 1.0, "step": 1.0}),
                         "Yaw step 0 → 1 rad")
        self.assertEqual(self.pr.step_title({"channel": "z", "initial": 0.0, "target": 10.0, "step": None}),
                         "Altitude step 0 → 10 m")
        # A noisy start below 0.1 % of the step is shown as about zero; one above it with its digits.
        self.assertEqual(self.pr.step_title({"channel": "x", "initial": -0.0008464, "target": 2.0, "step": None}),
                         "X position step ≈0 → 2 m")
        self.assertEqual(self.pr.step_title({"channel": "x", "initial": -0.05, "target": 2.0, "step": None}),
                         "X position step −0.05 → 2 m")

    def test_steps_without_metrics_are_the_commanded_setpoints(self):
        # yaw_des 3.0 -> -3.0 at t = 1 s: detect_steps on the unwrapped data gives the commanded values.
        t = np.arange(301) / 100.0
        des = np.where(t < 1.0, 3.0, -3.0)
        cols = {"t": t, "yaw": des, "yaw_des": des}
        for ch in ("x", "y", "z", "roll", "pitch"):
            cols[ch] = np.zeros(301)
            cols[ch + "_des"] = np.full(301, math.nan)
        names = list(cols)
        recorded = {"yaw": des.copy(), "yaw_des": des.copy()}
        data = np.column_stack([self.pr.unwrap_angle(cols[n]) if n in recorded else cols[n] for n in names])
        steps = self.pr.detect_steps(self.pr.Trajectory("mem", names, data, recorded))
        self.assertEqual(len(steps), 1)
        s = steps[0]
        self.assertEqual((s["channel"], s["t_step_s"], s["initial"], s["target"]), ("yaw", 1.0, 3.0, -3.0))
        self.assertAlmostEqual(s["step"], 2 * math.pi - 6.0, places=12)

    def test_intervals_cover_the_flagged_rows(self):
        t = np.arange(301) / 100.0
        flags = np.zeros(301)
        flags[50:180] = 1
        flags[300] = 1
        spans = self.pr.saturated_intervals(t, flags)
        self.assertEqual(len(spans), 2)
        self.assertAlmostEqual(spans[0][0], 0.50, places=12)
        self.assertAlmostEqual(spans[0][1], 1.80, places=12)
        # Total = flagged rows x period, the count metrics.json reports.
        self.assertAlmostEqual(sum(b - a for a, b in spans), np.count_nonzero(flags) * 0.01, places=9)
        self.assertEqual(self.pr.saturated_intervals(t, np.zeros(301)), [])

    def test_shading_is_drawn_only_where_saturated(self):
        import matplotlib.pyplot as plt
        t = np.arange(201) / 100.0
        cols = {"t": t, "sat1": np.zeros(201), "sat2": (t < 0.5).astype(float), "sat3": np.zeros(201),
                "sat4": ((t >= 1.0) & (t < 1.2)).astype(float), "tilt_sat": np.zeros(201)}
        names = list(cols)
        traj = self.pr.Trajectory("mem", names, np.column_stack([cols[n] for n in names]))
        fig, ax = plt.subplots()
        handles = self.pr.shade_saturation(ax, traj)
        spans = sorted((p.get_xy()[0][0], p.get_xy()[2][0]) for p in ax.patches)
        plt.close(fig)
        self.assertEqual(len(spans), 2)
        self.assertAlmostEqual(spans[0][0], 0.0)
        self.assertAlmostEqual(spans[0][1], 0.5)
        self.assertAlmostEqual(spans[1][0], 1.0)
        self.assertAlmostEqual(spans[1][1], 1.2)
        self.assertEqual(len(handles), 1)
        self.assertIn("rotors 2, 4 saturated", handles[0].get_label())

    def test_a_hexarotors_fifth_and_sixth_rotors_are_shaded(self):
        # Only sat1..sat6 columns (no w, no cmd): the rotor count comes from whichever per-rotor
        # columns the file has, so rotor 6 saturating is drawn and named.
        import matplotlib.pyplot as plt
        t = np.arange(101) / 100.0
        cols = {"t": t, "tilt_sat": np.zeros(101)}
        for k in range(1, 7):
            cols[f"sat{k}"] = ((k == 6) & (t >= 0.3) & (t < 0.4)).astype(float)
        names = list(cols)
        traj = self.pr.Trajectory("mem", names, np.column_stack([cols[n] for n in names]))
        self.assertEqual(traj.rotor_count(), 6)
        fig, ax = plt.subplots()
        handles = self.pr.shade_saturation(ax, traj)
        plt.close(fig)
        self.assertEqual(len(handles), 1)
        self.assertIn("rotor 6 saturated", handles[0].get_label())

    def test_motors_off_on_the_ground_are_not_shaded(self):
        # Rows 0..49 rest on the ground with every command 0 (a disarmed flight stack): not shaded; rows
        # 100..119 have the same commands in the air (z > 0): shaded, as the limits figures count them.
        import matplotlib.pyplot as plt
        t = np.arange(201) / 100.0
        resting = t < 0.5
        falling = (t >= 1.0) & (t < 1.2)
        off = resting | falling
        cols = {"t": t, "z": np.where(resting, 0.0, 1.0), "vz": np.where(resting, 0.0, -0.5),
                "tilt_sat": np.zeros(201)}
        for k in range(1, 5):
            cols[f"sat{k}"] = off.astype(float)
            cols[f"cmd{k}"] = np.where(off, 0.0, 5000.0)
        names = list(cols)
        traj = self.pr.Trajectory("mem", names, np.column_stack([cols[n] for n in names]))
        fig, ax = plt.subplots()
        handles = self.pr.shade_saturation(ax, traj)
        spans = sorted((p.get_xy()[0][0], p.get_xy()[2][0]) for p in ax.patches)
        plt.close(fig)
        self.assertEqual(len(spans), 1)
        self.assertAlmostEqual(spans[0][0], 1.0)
        self.assertAlmostEqual(spans[0][1], 1.2)
        self.assertIn("(0.20 s shown)", handles[0].get_label())


class StepOnTraceTest(unittest.TestCase):
    """The target, band and setpoint of a step figure lie on the trace as drawn (an angle unwrapped
    from the first row), with the settling band metrics.json gives."""

    @classmethod
    def setUpClass(cls):
        if importlib.util.find_spec("matplotlib") is None:
            raise unittest.SkipTest("matplotlib not importable in this interpreter")
        spec = importlib.util.spec_from_file_location("plot_run", SCRIPT)
        cls.pr = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(cls.pr)

    def draw(self, run_dir):
        """plot_step on the run's first step; the figure it drew (kept open for inspection)."""
        traj = self.pr.load_trajectory(os.path.join(run_dir, "trajectory.csv"))
        metrics = self.pr.load_metrics(os.path.join(run_dir, "metrics.json"))
        step = metrics["steps"][0]
        figs = []
        from unittest import mock
        with mock.patch.object(self.pr.plt, "close", side_effect=figs.append):
            self.pr.plot_step(traj, step, (0.0, float(traj["t"][-1])), os.path.join(run_dir, "s.png"), metrics, True)
        figs = [f for f in figs if isinstance(f, self.pr.matplotlib.figure.Figure)]
        self.assertEqual(len(figs), 1, figs)
        self.addCleanup(self.pr.plt.close, figs[0])
        return figs[0]

    @staticmethod
    def band_of(fig):
        ax = fig.axes[0]
        (band,) = [c for c in ax.collections if len(c.get_paths()) == 1]
        y = band.get_paths()[0].vertices[:, 1]
        return float(y.min()), float(y.max())

    @staticmethod
    def labels(fig):
        return [t.get_text() for leg in fig.legends for t in leg.get_texts()]

    def write_yaw_run(self, run_dir, band_pct):
        # Yaw drifts 3.10 -> 3.20 rad over 2 s, so the record wraps past pi (to -3.08) before the
        # step; at t = 2 s the setpoint steps by +0.2 rad to 3.40 (recorded -2.883). metrics.json
        # gives initial wrapped at the step sample, as the C++ side writes it.
        os.makedirs(run_dir)
        t = np.arange(0, 8.0001, 0.01)
        true = np.where(t < 2.0, 3.10 + 0.05 * t, 3.40 - 0.2 * np.exp(-(t - 2.0) / 0.4))
        des = np.where(t < 2.0, 3.10, 3.40)
        wrap = lambda a: np.remainder(a + math.pi, 2 * math.pi) - math.pi  # noqa: E731
        cols = {c: np.zeros_like(t) for c in self.pr.REQUIRED_COLUMNS}
        cols.update(t=t, yaw=wrap(true), yaw_des=wrap(des), z=np.full_like(t, 10.0))
        self.assertLess(cols["yaw"][199], -3.0)  # wrapped before the step
        np.savetxt(os.path.join(run_dir, "trajectory.csv"), np.column_stack([cols[c] for c in cols]),
                   delimiter=",", header=",".join(cols), comments="")
        k = int(np.searchsorted(t, 2.0))
        initial, target = float(cols["yaw"][k]), float(cols["yaw_des"][-1])
        self.assertAlmostEqual(initial, 3.20 - 2 * math.pi, places=9)
        step = {"channel": "yaw", "t_step_s": 2.0, "initial": initial, "target": target,
                "step": math.remainder(target - initial, 2 * math.pi),
                "figures": {"settling_time_2pct_s": 1.5}, "criteria": [], "passed": True}
        if band_pct is not None:
            step["settling_band_pct"] = band_pct
        with open(os.path.join(run_dir, "metrics.json"), "w") as f:
            json.dump({"scenario": "wrap", "steps": [step]}, f)

    def test_angle_wrapped_before_the_step_gets_its_band_on_the_trace(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "run")
            self.write_yaw_run(run, band_pct=None)
            fig = self.draw(run)
            # Target 3.40 rad on the unwrapped trace, band 2 % of the 0.2 rad step: +-0.004 rad.
            lo, hi = self.band_of(fig)
            self.assertAlmostEqual(lo, 3.396, places=9)
            self.assertAlmostEqual(hi, 3.404, places=9)
            des = [ln for ln in fig.axes[0].lines if ln.get_label() == "setpoint yaw_des"][0].get_ydata()
            self.assertAlmostEqual(float(des[0]), 3.10, places=9)
            self.assertAlmostEqual(float(des[-1]), 3.40, places=9)
            self.assertTrue(any(lb.startswith("±2 % band (3.4 ±") for lb in self.labels(fig)), self.labels(fig))

    def test_band_is_the_settling_band_of_metrics_json(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "run")
            self.write_yaw_run(run, band_pct=5)
            fig = self.draw(run)
            lo, hi = self.band_of(fig)  # 5 % of 0.2 rad
            self.assertAlmostEqual(lo, 3.39, places=9)
            self.assertAlmostEqual(hi, 3.41, places=9)
            labels = self.labels(fig)
            self.assertTrue(any(lb.startswith("±5 % band") for lb in labels), labels)
            self.assertIn("5 % settling at 1.50 s", labels)
            self.assertIn("settle 5%", "\n".join(t.get_text() for t in fig.texts))
            self.assertNotIn("2 %", " ".join(labels))
            # A band that is no positive number is a malformed metrics.json.
            with open(os.path.join(run, "metrics.json")) as f:
                m = json.load(f)
            m["steps"][0]["settling_band_pct"] = "wide"
            with open(os.path.join(run, "metrics.json"), "w") as f:
                json.dump(m, f)
            with self.assertRaisesRegex(self.pr.InputError, "settling_band_pct"):
                self.pr.load_metrics(os.path.join(run, "metrics.json"))


class TrackingPlotTest(unittest.TestCase):
    """tracking_*.png for a run whose metrics.json has "tracking", and the errors they draw."""

    TRACKING_PNGS = ("tracking_path.png", "tracking_axes.png", "tracking_error.png")

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="plot_run_tracking_")
        self.tmp = self._tmp.name
        self.env = dict(os.environ, MPLCONFIGDIR=os.path.join(self.tmp, "mplconfig"))

    def tearDown(self):
        self._tmp.cleanup()

    def run_script(self, run_dir):
        return subprocess.run([plot_python(), SCRIPT, run_dir], capture_output=True, text=True,
                              timeout=180, env=self.env)

    def test_tracking_figures_are_written_for_a_tracking_run(self):
        run = os.path.join(self.tmp, "run")
        make_tracking_run(run)
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        sizes = {"tracking_path.png": ((1500, 650), (2400, 1000)),  # 13 x 5.5 in at 150 dpi
                 "tracking_axes.png": ((1300, 1000), (1700, 1400)),  # 10 x 8 in
                 "tracking_error.png": ((1300, 1200), (1700, 1500))}  # 10 x 8.9 in with the Psi row
        for name in self.TRACKING_PNGS:
            path = os.path.join(run, name)
            self.assertIn(path, res.stdout.splitlines())
            w, h = png_size(path)
            (w0, h0), (w1, h1) = sizes[name]
            self.assertTrue(w0 <= w <= w1 and h0 <= h <= h1, f"{name}: implausible size {w}x{h}")
            self.assertGreater(os.path.getsize(path), 20_000, name)

    def test_without_psi_the_error_figure_has_two_rows(self):
        run = os.path.join(self.tmp, "run")
        make_tracking_run(run, psi=False)
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        _, h = png_size(os.path.join(run, "tracking_error.png"))
        self.assertLess(h, 1100)  # (2 x 2.7 + 0.8) in at 150 dpi = 930 px

    def test_no_tracking_figures_without_tracking_in_metrics(self):
        run = os.path.join(self.tmp, "run")
        make_tracking_run(run, tracking=False)
        res = self.run_script(run)
        self.assertEqual(res.returncode, 0, res.stderr)
        for name in self.TRACKING_PNGS:
            self.assertFalse(os.path.exists(os.path.join(run, name)), name)

    def test_errors_are_counted_at_the_controller_steps(self):
        if importlib.util.find_spec("matplotlib") is None:
            self.skipTest("matplotlib not importable in this interpreter")
        spec = importlib.util.spec_from_file_location("plot_run", SCRIPT)
        pr = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(pr)
        run = os.path.join(self.tmp, "run")
        make_tracking_run(run, offset_x=0.03)
        traj = pr.load_trajectory(os.path.join(run, "trajectory.csv"))
        e = pr.tracking_errors(traj, 0.02)
        # Every other sample (t = 0, 0.02, ...): there the reference is current, the error the 3 cm in x.
        self.assertEqual(len(e["t"]), 1001)
        np.testing.assert_allclose(e["x"], 0.03, atol=1e-12)
        np.testing.assert_allclose(e["y"], 0.0, atol=1e-12)
        np.testing.assert_allclose(e["norm"], 0.03, atol=1e-12)
        np.testing.assert_allclose(e["psi"], 1e-4)
        # Every sample: the held reference lags the vehicle by up to v dt = 1.257 m/s x 10 ms.
        every = pr.tracking_errors(traj, 0.0)
        self.assertEqual(len(every["t"]), 2001)
        self.assertGreater(every["norm"].max(), 0.03 + 0.005)


if __name__ == "__main__":
    unittest.main()
