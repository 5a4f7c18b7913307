#!/usr/bin/python3
"""Plot a quadcosim run directory.

Usage: plot_run.py RUN_DIR

Reads RUN_DIR/trajectory.csv (required) and RUN_DIR/metrics.json (optional) and
writes PNG figures into RUN_DIR, printing the path of every file written:

  step_<channel>.png  one per entry of metrics.json "steps" (or, without
                      metrics.json, one per channel whose <channel>_des column
                      changes during the run, or is constant but differs from
                      the channel's value in the first row), in the style of the paper's
                      Figs. 4-7: variable (red) and its rate (blue) vs. time,
                      setpoint dashed grey, settling band around the target
                      (+-2 % unless metrics.json gives the step's
                      settling_band_pct), peak / settling markers and a box with the step
                      figures next to the paper's reference figures.
                      A channel stepped more than once gets
                      step_<channel>.png, step_<channel>_2.png, ...
                      Each step plot spans the whole run, except that it ends
                      at the next step of the same channel and, in long runs,
                      at max(15 s, 2.5 x settling time) after the step.
  overview.png        2x3 grid: 3D path, position, attitude, body rates,
                      rotor speeds, vertical speed.
  outputs.png         when trajectory.csv has out.<name> columns (the
                      figures the controller declares): one panel per
                      group of names sharing a prefix ("e_x.x", "e_x.y",
                      "e_x.z") or per name, against time.
  tracking_path.png   when metrics.json has "tracking" (the run tracked a
                      trajectory): the 3D path against the reference, and
                      the top view (x-y), side by side.
  tracking_axes.png   x, y, z against their reference over time.
  tracking_error.png  the position error (reference - measured) at the
                      samples the figures count (the controller's steps, at
                      the multiples of metrics.json's reference_period_s):
                      its norm and each axis over time, and the attitude
                      error Psi (column att_err) when the controller reports
                      one; the samples before after_s are greyed and the
                      y-axes fit the judged ones.

Conventions assumed for metrics.json: the time figures (peak_time_s, rise_time_s,
t95_s, settling_time_2pct_s) are measured from the step time t_step_s; the
settling band is settling_band_pct (2 when absent) % of the step size
|target - initial| (of |target| if the step size is zero), and settling_time_2pct_s
is the settling time in that band, whatever its width. An angle is drawn
unwrapped from the first row; initial (wrapped, at the step sample) and target
are moved by the whole turns that put them on that trace.

Only the Python standard library, numpy and matplotlib (Debian 12 packages)
are used; the Agg backend is forced, so no display is needed.

Exit status: 0 on success, 1 when an input file is missing or malformed
(the message names the file, and the column / key when relevant), 2 on a
command-line usage error.
"""

import argparse
import json
import math
import os
import sys
import textwrap
import warnings

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (backend must be chosen first)
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

PROG = "plot_run.py"

# Columns this script uses (looked up by name; any other column is ignored).
REQUIRED_COLUMNS = (
    "t", "x", "y", "z", "vx", "vy", "vz",
    "roll", "pitch", "yaw", "p", "q", "r",
    "w1", "w2", "w3", "w4",
    "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des",
)

# Read when present (saturation flags, the attitude error Psi, the commands at the plant; docs/outputs.md);
# older trajectories lack them.
SATURATION_COLUMNS = ("sat1", "sat2", "sat3", "sat4", "tilt_sat")
# Rotors 5..8 of a hexarotor or octorotor (docs/outputs.md: w1..wN, cmd1..cmdN, sat1..satN).
EXTRA_ROTOR_COLUMNS = tuple(f"{c}{k}" for k in range(5, 9) for c in ("w", "cmd", "sat"))
OPTIONAL_COLUMNS = SATURATION_COLUMNS + ("att_err", "cmd1", "cmd2", "cmd3", "cmd4") + EXTRA_ROTOR_COLUMNS
# The controller's own figures: trajectory.csv's columns out.<name>, read when present.
OUTPUT_PREFIX = "out."
# At most this many panels in outputs.png; the names beyond are listed in its title.
MAX_OUTPUT_PANELS = 12
# Angles are drawn unwrapped (no 2 pi jumps), their setpoints too.
ANGLE_COLUMNS = ("roll", "pitch", "yaw", "roll_des", "pitch_des", "yaw_des")
COLOR_SATURATED = "#d62728"
COLOR_TILT_LIMIT = "#ff7f0e"

# channel -> display metadata
CHANNELS = {
    "x": dict(name="X position", sym="x", unit="m", rate="vx", rate_sym="vx", rate_unit="m/s"),
    "y": dict(name="Y position", sym="y", unit="m", rate="vy", rate_sym="vy", rate_unit="m/s"),
    "z": dict(name="Altitude", sym="z", unit="m", rate="vz", rate_sym="vz = dz/dt", rate_unit="m/s"),
    "roll": dict(name="Roll", sym="roll φ", unit="rad", rate="p", rate_sym="p (roll rate)",
                 rate_unit="rad/s"),
    "pitch": dict(name="Pitch", sym="pitch θ", unit="rad", rate="q", rate_sym="q (pitch rate)",
                  rate_unit="rad/s"),
    "yaw": dict(name="Yaw", sym="yaw ψ", unit="rad", rate="r", rate_sym="r (yaw rate)",
                rate_unit="rad/s"),
}
CHANNEL_ORDER = ("x", "y", "z", "roll", "pitch", "yaw")

# figure key -> (short label, unit, format)
FIGURE_INFO = {
    "overshoot_pct": ("overshoot", "%", "{:.1f}"),
    "peak_time_s": ("peak time", "s", "{:.2f}"),
    "rise_time_s": ("rise time", "s", "{:.2f}"),
    "t95_s": ("t95", "s", "{:.2f}"),
    "settling_time_2pct_s": ("settle 2%", "s", "{:.2f}"),
    "steady_state_error_pct": ("ss error", "%", "{:.2f}"),
}
FIGURE_ORDER = tuple(FIGURE_INFO)
# The settling band when metrics.json gives none (percent of the step size).
DEFAULT_SETTLING_BAND_PCT = 2.0

STEP_FIGSIZE = (8.0, 5.0)
OVERVIEW_FIGSIZE = (15.0, 9.0)
DPI = 150

COLOR_VAR = "#d62728"     # red, as in the paper
COLOR_RATE = "#1f4fd6"    # blue, as in the paper
COLOR_SETPOINT = "0.45"   # grey
COLOR_BAND = "#2ca02c"
COLOR_SETTLE = "#2a7f2a"
COLOR_PEAK = "#7a0000"


class InputError(Exception):
    """An input file is missing or malformed; the message names the file."""


# --------------------------------------------------------------------------- input


class Trajectory:
    """Column-name access to the numeric columns of trajectory.csv."""

    def __init__(self, path, columns, data, recorded=None):
        self.path = path
        self._index = {name: i for i, name in enumerate(columns)}
        self._data = data
        # Angle columns as recorded, before unwrapping (name -> array); absent: as in data.
        self._recorded = recorded or {}

    def recorded(self, name):
        """The column as trajectory.csv holds it (angles wrapped, setpoints as commanded)."""
        return self._recorded[name] if name in self._recorded else self[name]

    def __getitem__(self, name):
        return self._data[:, self._index[name]]

    def has(self, name):
        return name in self._index

    def output_names(self):
        """The controller's declared figures (the out.<name> columns), in the file's order."""
        return [c[len(OUTPUT_PREFIX):] for c in self._index if c.startswith(OUTPUT_PREFIX)]

    def __len__(self):
        return self._data.shape[0]

    def rotor_count(self):
        """How many rotors the run's vehicle has: the highest k of its per-rotor columns (wk, cmdk,
        satk; 4 to 8), 0 when the file has none."""
        return max((k for k in range(1, 9) if any(self.has(f"{c}{k}") for c in ("w", "cmd", "sat"))),
                   default=0)


def _find_bad_line(path, header_len, indices):
    """Slow path, only after numpy failed: locate the first unparsable line."""
    needed = max(indices) + 1
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        f.readline()
        for lineno, line in enumerate(f, start=2):
            if not line.strip():
                continue
            fields = line.rstrip("\r\n").split(",")
            if len(fields) < needed:
                return (f"line {lineno} has {len(fields)} fields, the header has {header_len}")
            for i in indices:
                try:
                    float(fields[i])
                except ValueError:
                    return f"line {lineno}: cannot parse {fields[i].strip()!r} as a number"
    return None


def load_trajectory(path):
    if not os.path.isfile(path):
        raise InputError(f"{path}: file not found (trajectory.csv is required)")
    try:
        with open(path, newline="", encoding="utf-8") as f:
            header = f.readline()
            if not header.strip():
                raise InputError(f"{path}: empty file or empty header line")
            names = [h.strip().strip('"') for h in header.lstrip("\ufeff").rstrip("\r\n").split(",")]
            index = {}
            for i, name in enumerate(names):
                if name in index and name in REQUIRED_COLUMNS:
                    raise InputError(f"{path}: column {name!r} appears more than once in the header")
                index.setdefault(name, i)
            missing = [c for c in REQUIRED_COLUMNS if c not in index]
            if missing:
                raise InputError(
                    f"{path}: missing required column{'s' if len(missing) > 1 else ''} "
                    + ", ".join(repr(c) for c in missing)
                    + f" (header has: {', '.join(names)})")
            outputs = tuple(n for n in index if n.startswith(OUTPUT_PREFIX))
            loaded = REQUIRED_COLUMNS + tuple(c for c in OPTIONAL_COLUMNS if c in index) + outputs
            usecols = [index[c] for c in loaded]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "input contained no data"
                try:
                    data = np.loadtxt(f, delimiter=",", usecols=usecols, ndmin=2, dtype=np.float64,
                                      comments=None, encoding="utf-8")
                except ValueError as exc:
                    detail = _find_bad_line(path, len(names), usecols) or str(exc)
                    raise InputError(f"{path}: malformed data: {detail}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not a UTF-8 text file ({exc})") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    if data.shape[0] == 0:
        raise InputError(f"{path}: no data rows after the header")
    recorded = {}
    for name in ANGLE_COLUMNS:
        col = loaded.index(name)
        recorded[name] = data[:, col].copy()
        data[:, col] = unwrap_angle(data[:, col])
    traj = Trajectory(path, loaded, data, recorded)
    t = traj["t"]
    if not np.all(np.isfinite(t)):
        raise InputError(f"{path}: column 't' contains non-finite values")
    if len(t) > 1 and np.any(np.diff(t) < 0):
        print(f"{PROG}: warning: {path}: column 't' is not monotonically non-decreasing",
              file=sys.stderr)
    return traj


def unwrap_angle(a):
    """The angle with every jump of more than pi between finite neighbours taken the short way
    (as the step figures judge it); NaN entries stay NaN and do not break the unwrapping."""
    a = np.array(a, dtype=np.float64)
    ok = np.isfinite(a)
    if np.count_nonzero(ok) > 1:
        a[ok] = np.unwrap(a[ok])
    return a


def saturated_intervals(t, flags):
    """[(t_start, t_end)] of the runs of rows with a flag set; each row stands for the tick period
    after it (the last row for the one before), as the saturation figures count it."""
    t = np.asarray(t, dtype=np.float64)
    on = np.asarray(flags) != 0
    if t.size == 0 or not on.any():
        return []
    period = float(t[1] - t[0]) if t.size > 1 else 0.0
    ends = np.append(t[1:], t[-1] + period)
    out = []
    i = 0
    n = t.size
    while i < n:
        if on[i]:
            j = i
            while j + 1 < n and on[j + 1]:
                j += 1
            out.append((float(t[i]), float(ends[j])))
            i = j + 1
        else:
            i += 1
    return out


def shade_saturation(ax, traj, lo=None, hi=None):
    """Shades the intervals where a rotor was saturated (red) or the tilt limit acted (orange);
    returns legend handles for what was shaded."""
    handles = []
    if not all(traj.has(c) for c in SATURATION_COLUMNS):
        return handles
    t = traj["t"]
    # Resting on the ground (z = 0, vz = 0) with every command at 0 is motors off (a flight stack
    # disarmed before take-off or after landing), not saturation: the limits figures skip those rows.
    off = np.zeros(len(t), dtype=bool)
    if all(traj.has(c) for c in ("z", "vz", "cmd1", "cmd2", "cmd3", "cmd4")):
        off = (traj["z"] <= 0.0) & (traj["vz"] == 0.0)
        for k in range(1, traj.rotor_count() + 1):
            off &= traj[f"cmd{k}"] <= 0.0
    any_rotor = np.zeros(len(t), dtype=bool)
    rotors = []
    for k in range(1, traj.rotor_count() + 1):
        sat = (traj[f"sat{k}"] != 0) & ~off
        if np.any(sat):
            rotors.append(str(k))
        any_rotor |= sat
    for flags, color, label in ((any_rotor, COLOR_SATURATED, f"rotor{'s' if len(rotors) > 1 else ''} "
                                 f"{', '.join(rotors)} saturated"),
                                (traj["tilt_sat"] != 0, COLOR_TILT_LIMIT, "tilt limit acting")):
        spans = saturated_intervals(t, flags)
        if lo is not None:
            spans = [(max(a, lo), min(b, hi)) for a, b in spans if b > lo and a < hi]
        for a, b in spans:
            ax.axvspan(a, b, color=color, alpha=0.12, lw=0, zorder=0)
        if spans:
            total = sum(b - a for a, b in spans)
            handles.append(Patch(facecolor=color, alpha=0.3, label=f"{label} ({total:.2f} s shown)"))
    return handles


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _num_or_none(v, where):
    if v is None:
        return None
    if not _is_number(v):
        raise InputError(f"{where}: expected a number or null, got {v!r}")
    v = float(v)
    return v if math.isfinite(v) else None


def load_metrics(path):
    """Returns the validated metrics dict, or None when the file does not exist."""
    if not os.path.exists(path):
        return None
    try:
        with open(path, encoding="utf-8") as f:
            obj = json.load(f)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: invalid JSON: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    if not isinstance(obj, dict):
        raise InputError(f"{path}: top level must be a JSON object")
    steps = obj.get("steps")
    if not isinstance(steps, list):
        raise InputError(f"{path}: missing or non-list key 'steps'")
    judged = obj.get("judged", "spec")
    if judged not in ("spec", "paper", "none"):
        raise InputError(f"{path}: key 'judged' must be 'spec', 'paper' or 'none', got {judged!r}")
    clean = []
    for i, s in enumerate(steps):
        where = f"{path}: steps[{i}]"
        if not isinstance(s, dict):
            raise InputError(f"{where}: must be a JSON object")
        ch = s.get("channel")
        if ch not in CHANNELS:
            raise InputError(f"{where}: key 'channel' must be one of {', '.join(CHANNEL_ORDER)}, "
                             f"got {ch!r}")
        step = {"channel": ch}
        for key in ("t_step_s", "initial", "target"):
            if key not in s:
                raise InputError(f"{where}: missing key {key!r}")
            v = s[key]
            if not _is_number(v) or not math.isfinite(float(v)):
                raise InputError(f"{where}: key {key!r} must be a finite number, got {v!r}")
            step[key] = float(v)
        # The step judged (shortest path for an angle) and the verdict; absent in older files.
        step["step"] = float(s["step"]) if _is_number(s.get("step")) and math.isfinite(float(s["step"])) else None
        step["verdict"] = str(s["verdict"]) if isinstance(s.get("verdict"), str) else None
        band = s.get("settling_band_pct", DEFAULT_SETTLING_BAND_PCT)  # absent in older files
        if not _is_number(band) or not math.isfinite(float(band)) or float(band) <= 0:
            raise InputError(f"{where}: key 'settling_band_pct' must be a positive number, got {band!r}")
        step["settling_band_pct"] = float(band)
        figures = s.get("figures") or {}
        if not isinstance(figures, dict):
            raise InputError(f"{where}: key 'figures' must be an object")
        step["figures"] = {k: _num_or_none(v, f"{where}.figures.{k}") for k, v in figures.items()}
        reference = s.get("reference") or {}
        if not isinstance(reference, dict):
            raise InputError(f"{where}: key 'reference' must be an object")
        ref = {}
        for k, v in reference.items():
            if k == "source":
                ref[k] = str(v)
            elif _is_number(v) or v is None:
                ref[k] = _num_or_none(v, f"{where}.reference.{k}")
        step["reference"] = ref
        criteria = s.get("criteria") or []
        if not isinstance(criteria, list) or not all(isinstance(c, dict) for c in criteria):
            raise InputError(f"{where}: key 'criteria' must be a list of objects")
        step["criteria"] = criteria
        passed = s.get("passed")
        if not isinstance(passed, bool) and judged != "none":
            # Only the judged set's criteria give the verdict ("judged" absent in older files: all are).
            flags = [c.get("passed") for c in criteria
                     if isinstance(c.get("passed"), bool) and c.get("judged", True) is True]
            passed = all(flags) if flags else None
        step["passed"] = passed if isinstance(passed, bool) else None
        clean.append(step)
    return {
        "scenario": str(obj.get("scenario", "")),
        "description": str(obj.get("description", "")),
        # The criteria set judged: spec, paper or none (figures only); older files judged their one set.
        "judged": judged,
        "passed": obj.get("passed") if isinstance(obj.get("passed"), bool) else None,
        "steps": clean,
        # Position-hold figures (analysis.hold), passed through as written; None without one.
        "hold": obj.get("hold") if isinstance(obj.get("hold"), dict) else None,
        # Saturation figures and limits, passed through as written; None without them.
        "saturation": obj.get("saturation") if isinstance(obj.get("saturation"), dict) else None,
        # Tracking figures (a trajectory or analysis.tracking), passed through; None without them.
        "tracking": obj.get("tracking") if isinstance(obj.get("tracking"), dict) else None,
        # What flew and how (docs/outputs.md, "Provenance"); None in files written before it.
        "provenance": obj.get("provenance") if isinstance(obj.get("provenance"), dict) else None,
    }


def controller_label(metrics):
    """The label of the controller that flew (provenance.controller.label: "se3", "python mod:Class",
    "fmu x.fmu"), or "" when metrics.json does not say (written before provenance)."""
    c = ((metrics or {}).get("provenance") or {}).get("controller")
    if not isinstance(c, dict):
        return ""
    for key in ("label", "type"):
        if isinstance(c.get(key), str) and c[key]:
            return c[key]
    return ""


def controller_replaced(metrics):
    """True when another controller flew than the one the scenario file names (--controller, or a
    Python object given to quadcosim.run()): the file's description then speaks of the wrong one."""
    c = ((metrics or {}).get("provenance") or {}).get("controller")
    if not isinstance(c, dict):
        return False
    if isinstance(c.get("scenario_type"), str) and isinstance(c.get("type"), str) and c["scenario_type"] != c["type"]:
        return True
    return isinstance(c.get("override"), str) and c.get("override") not in ("", c.get("scenario_type"))


def run_subtitle_parts(metrics):
    """["scenario NAME", "controller LABEL"] as known: the start of every plot's subtitle."""
    parts = []
    if metrics and metrics.get("scenario"):
        parts.append(f"scenario {metrics['scenario']}")
    label = controller_label(metrics)
    if label:
        parts.append(f"controller {label}")
    return parts


def detect_steps(traj):
    """Without metrics.json: one step per channel whose setpoint changes."""
    t = traj["t"]
    steps = []
    for ch in CHANNEL_ORDER:
        des = traj[f"{ch}_des"]
        finite = np.isfinite(des)
        if not finite.any():
            continue
        d = des[finite]
        first = d[0]
        tol = 1e-9 * max(1.0, float(np.max(np.abs(d))))
        changed = np.nonzero(np.abs(d - first) > tol)[0]
        if changed.size == 0:
            # Setpoint constant from the first row (e.g. z_des = 10 from t = 0)
            # but the state starts elsewhere (by > 1 mm or 1 mrad): a step at the start.
            y0 = traj[ch][finite][0]
            if np.isfinite(y0) and abs(first - y0) > max(1e-3, 1e-3 * abs(first)):
                steps.append({
                    "channel": ch, "t_step_s": float(t[finite][0]),
                    "initial": float(y0), "target": float(first),
                    "step": (math.remainder(float(first) - float(y0), 2 * math.pi)
                             if ch in ("roll", "pitch", "yaw") else None),
                    "settling_band_pct": DEFAULT_SETTLING_BAND_PCT,
                    "figures": {}, "reference": {}, "criteria": [], "passed": None,
                })
            continue
        k = changed[0]
        # The step as commanded (the recorded setpoints), and for an angle the shortest path it is
        # flown on, as metrics.json gives it.
        commanded = traj.recorded(f"{ch}_des")[finite]
        initial, target = float(commanded[0]), float(commanded[-1])
        steps.append({
            "channel": ch,
            "t_step_s": float(t[finite][k]),
            "initial": initial,
            "target": target,
            "step": math.remainder(target - initial, 2 * math.pi) if ch in ("roll", "pitch", "yaw") else None,
            "settling_band_pct": DEFAULT_SETTLING_BAND_PCT,
            "figures": {}, "reference": {}, "criteria": [], "passed": None,
        })
    return steps


# --------------------------------------------------------------------------- plotting helpers


def _fmt_num(v):
    """Compact number for titles: 10 -> '10', 0.1 -> '0.1', -0.15 -> '−0.15'."""
    s = f"{v:.4g}"
    if s in ("-0", "-0.0"):
        s = "0"
    return s.replace("-", "−")


def step_title(step):
    """'Yaw step 3 → −3 rad': the step as commanded (its initial value and the target the setpoint was
    set to); for an angle whose shortest path differs from target − initial (a turn through ±pi, or a
    target more than pi away), that path too: 'Yaw step 3 → −3 rad (shortest path +0.2832 rad, to 3.283)'."""
    meta = CHANNELS[step["channel"]]
    unit = meta["unit"]
    initial, target = step["initial"], step["target"]
    # A measured start within 0.1 % of the step of zero (sensor noise before a position step) reads as
    # ≈0: its digits are in the figures, not worth the title's space.
    near_zero = initial != 0 and abs(initial) < 1e-3 * abs(target - initial)
    title = f"{meta['name']} step {'≈0' if near_zero else _fmt_num(initial)} → {_fmt_num(target)} {unit}"
    d = step.get("step")
    if step["channel"] in ("roll", "pitch", "yaw") and d is not None and abs(d - (target - initial)) > 1e-9:
        sign = "+" if d >= 0 else "−"
        title += f" (shortest path {sign}{_fmt_num(abs(d))} {unit}, to {_fmt_num(initial + d)})"
    return title


def _figure_cell(key, value):
    if value is None:
        return "—"
    label, unit, fmt = FIGURE_INFO.get(key, (None, _unit_from_key(key), "{:.4g}"))
    return f"{fmt.format(value)} {unit}".strip()


def _unit_from_key(key):
    if key.endswith("_pct"):
        return "%"
    if key.endswith("_s"):
        return "s"
    return ""


def _figure_label(key, settling_band_pct=DEFAULT_SETTLING_BAND_PCT):
    """A figure's short label; the settling time's names its band ("settle 5%")."""
    if key == "settling_time_2pct_s":
        return f"settle {settling_band_pct:g}%"
    if key in FIGURE_INFO:
        return FIGURE_INFO[key][0]
    base = key
    for suffix in ("_pct", "_s"):
        if base.endswith(suffix):
            base = base[: -len(suffix)]
    return base.replace("_", " ")


def _criterion_line(c, settling_band_pct=DEFAULT_SETTLING_BAND_PCT):
    fig = str(c.get("figure", "?"))
    lo, hi = c.get("min"), c.get("max")
    lo = lo if _is_number(lo) else None
    hi = hi if _is_number(hi) else None
    if lo is not None and hi is not None:
        rng = f"in [{lo:g}, {hi:g}]"
    elif lo is not None:
        rng = f"≥ {lo:g}"
    elif hi is not None:
        rng = f"≤ {hi:g}"
    else:
        rng = "defined"
    passed = c.get("passed")
    if c.get("judged", True) is True:
        mark = "✓" if passed is True else ("✗" if passed is False else "?")
    else:  # the other set's band: shown, not judged
        mark = "·" if passed is True else ("○" if passed is False else "?")
    return f"{mark} {c.get('set', 'spec')}: {_figure_label(fig, settling_band_pct)} {rng}"


def _align_zero(ax_left, ax_right):
    """Put y = 0 at the same height on both axes of a twinx pair (as on a
    single shared axis in the paper's figures), without clipping data. The
    height of the zero line is chosen so that the data of both axes fill as
    much of their axis as possible; if aligning would squeeze either curve
    into less than half of the height, the axes are left independent."""
    a0, a1 = ax_left.get_ylim()
    b0, b1 = ax_right.get_ylim()
    a0, a1 = min(a0, 0.0), max(a1, 0.0)
    b0, b1 = min(b0, 0.0), max(b1, 0.0)
    if a1 <= a0 or b1 <= b0:
        return

    def span(lo, hi, f):  # smallest axis span with 0 at fraction f holding [lo, hi]
        return max(hi / (1.0 - f), -lo / f)

    best_f, best_fill = None, 0.0
    for f in np.linspace(0.02, 0.98, 97):
        fill = min((a1 - a0) / span(a0, a1, f), (b1 - b0) / span(b0, b1, f))
        if fill > best_fill:
            best_f, best_fill = float(f), fill
    if best_f is None or best_fill < 0.5:
        return
    sa, sb = span(a0, a1, best_f), span(b0, b1, best_f)
    ax_left.set_ylim(-best_f * sa, (1.0 - best_f) * sa)
    ax_right.set_ylim(-best_f * sb, (1.0 - best_f) * sb)


def _fit_twin_axes(fig, ax, ax2, left_min, right_max):
    """Shrink/shift a twinx pair horizontally so that its decorations (tick
    labels, axis labels) lie within [left_min, right_max] in figure coords."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    inv = fig.transFigure.inverted()
    left = ax.get_tightbbox(renderer).transformed(inv).x0
    right = ax2.get_tightbbox(renderer).transformed(inv).x1
    pos = ax.get_position()
    x0, x1 = pos.x0, pos.x1
    if left < left_min:
        x0 += left_min - left
    if right > right_max:
        x1 -= right - right_max
    if (x0, x1) != (pos.x0, pos.x1) and x1 - x0 > 0.2:
        for a in (ax, ax2):
            a.set_position([x0, pos.y0, x1 - x0, pos.height])


def _finite_minmax(*arrays):
    vals = [a[np.isfinite(a)] for a in arrays]
    vals = [v for v in vals if v.size]
    if not vals:
        return None
    return min(float(v.min()) for v in vals), max(float(v.max()) for v in vals)


def _equal_axes_3d(ax3, *pairs):
    """Equal scales on a 3D axes: one cube around both series of each (x, y, z) pair, at least 1 m."""
    lims = [_finite_minmax(a, b) or (0.0, 0.0) for a, b in pairs]
    half = max(0.5, max((b - a) for a, b in lims) / 2.0) * 1.05
    for setter, (a, b) in zip((ax3.set_xlim, ax3.set_ylim, ax3.set_zlim), lims):
        c = 0.5 * (a + b)
        setter(c - half, c + half)
    ax3.set_box_aspect((1, 1, 1))


# --------------------------------------------------------------------------- step figure


def step_on_trace(traj, step):
    """The step in the values of the trace as drawn: {"initial", "target", "half_band", "band_pct",
    "turns"}. An angle is drawn unwrapped from the first row, while metrics.json gives its initial
    value wrapped to (-pi, pi] at the step sample (the first with t >= t_step_s): initial moves by the
    whole turns 2 pi k ("turns" = 2 pi k) that bring it nearest the drawn trace there, and the target
    is initial + the shortest-path step. The band's half width is settling_band_pct % of |target -
    initial| (of |target| for a zero step). A position, or an angle without a finite sample at the
    step, is taken as given."""
    ch = step["channel"]
    initial, target = step["initial"], step["target"]
    band_pct = step.get("settling_band_pct", DEFAULT_SETTLING_BAND_PCT)
    span = abs(target - initial)
    half = band_pct / 100.0 * (span if span > 0 else abs(target))
    turns = 0.0
    if ch in ("roll", "pitch", "yaw"):
        if step.get("step") is not None:
            target = initial + step["step"]
            half = band_pct / 100.0 * (abs(step["step"]) if step["step"] != 0 else abs(step["target"]))
        t, y = traj["t"], traj[ch]
        k = int(np.searchsorted(t, step["t_step_s"], side="left"))
        if k < len(t) and np.isfinite(y[k]):
            turns = 2 * math.pi * round((float(y[k]) - initial) / (2 * math.pi))
    return {"initial": initial + turns, "target": target + turns, "half_band": half,
            "band_pct": band_pct, "turns": turns}


def plot_step(traj, step, window, out_path, metrics, has_metrics):
    ch = step["channel"]
    meta = CHANNELS[ch]
    t_all = traj["t"]
    lo, hi = window
    sel = (t_all >= lo) & (t_all <= hi)
    if np.count_nonzero(sel) < 2:
        sel = np.ones_like(t_all, dtype=bool)
    t = t_all[sel]
    y = traj[ch][sel]
    rate = traj[meta["rate"]][sel]
    des = traj[f"{ch}_des"][sel]

    t_step = step["t_step_s"]
    on_trace = step_on_trace(traj, step)
    initial, target, half = on_trace["initial"], on_trace["target"], on_trace["half_band"]
    band_pct = on_trace["band_pct"]
    if ch in ("roll", "pitch", "yaw"):
        # The setpoint, unwrapped from its own first row, by the whole turns that put it on the target.
        k = int(np.searchsorted(t, t_step, side="left"))
        if k < len(des) and np.isfinite(des[k]):
            des = des + 2 * math.pi * round((target - float(des[k])) / (2 * math.pi))
    figs = step["figures"]
    unit = meta["unit"]

    fig = plt.figure(figsize=STEP_FIGSIZE, dpi=DPI)
    ax = fig.add_axes([0.085, 0.115, 0.545, 0.745])
    ax2 = ax.twinx()

    handles = []
    # The settling band around the target, from the step time on
    t_end = float(t[-1])
    if half > 0 and t_end > t_step:
        ax.fill_between([max(t_step, float(t[0])), t_end], target - half, target + half,
                        color=COLOR_BAND, alpha=0.15, lw=0, zorder=1)
        handles.append(Patch(facecolor=COLOR_BAND, alpha=0.25,
                             label=f"±{band_pct:g} % band ({_fmt_num(target)} ± {half:.3g} {unit})"))

    h_des, = ax.plot(t, des, ls="--", color=COLOR_SETPOINT, lw=1.3, zorder=2,
                     label=f"setpoint {ch}_des")
    h_var, = ax.plot(t, y, color=COLOR_VAR, lw=1.8, zorder=4, label=f"{meta['sym']} [{unit}]")
    h_rate, = ax2.plot(t, rate, color=COLOR_RATE, lw=1.4, zorder=3,
                       label=f"{meta['rate_sym']} [{meta['rate_unit']}]")
    handles = [h_var, h_rate, h_des] + handles + shade_saturation(ax, traj, float(t[0]), float(t[-1]))

    # Peak marker (time figures are measured from the step time)
    peak_t = figs.get("peak_time_s")
    peak_line = None
    if peak_t is not None:
        tp = t_step + peak_t
        if t[0] <= tp <= t[-1]:
            yp = float(np.interp(tp, t, y))
            peak_line = (tp, yp)
            label = f"peak {_fmt_num(yp)} {unit} at {peak_t:.2f} s"
            if figs.get("overshoot_pct") is not None:
                label += f" ({figs['overshoot_pct']:.1f} %)"
            hp, = ax.plot([tp], [yp], marker="v" if target >= initial else "^", ms=8, color=COLOR_PEAK, ls="none", zorder=6,
                          label=label)
            handles.append(hp)

    # Settling time (in the step's band)
    ts_rel = figs.get("settling_time_2pct_s")
    if ts_rel is not None:
        ts = t_step + ts_rel
        if t[0] <= ts <= t[-1]:
            ys = float(np.interp(ts, t, y))
            ax.axvline(ts, color=COLOR_SETTLE, lw=1.2, ls="-.", zorder=3)
            hs, = ax.plot([ts], [ys], marker="o", ms=7, mfc="white", mec=COLOR_SETTLE, mew=1.8,
                          ls="none", zorder=6, label=f"{band_pct:g} % settling at {ts_rel:.2f} s")
            handles.append(hs)

    ax.set_xlim(float(t[0]), float(t[-1]) if t[-1] > t[0] else float(t[0]) + 1.0)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"{meta['sym']} [{unit}]", color=COLOR_VAR)
    ax2.set_ylabel(f"{meta['rate_sym']} [{meta['rate_unit']}]", color=COLOR_RATE)
    ax.tick_params(axis="y", colors=COLOR_VAR)
    ax2.tick_params(axis="y", colors=COLOR_RATE)
    ax.grid(True, color="0.88", lw=0.6)
    ax.set_zorder(ax2.get_zorder() + 1)  # red curve and markers above the blue one
    ax.patch.set_visible(False)
    _align_zero(ax, ax2)
    ax2.axhline(0.0, color="0.6", lw=0.6, zorder=0)
    if peak_line is not None:  # drop line from the peak to the time axis (after final y limits)
        tp, yp = peak_line
        ax.plot([tp, tp], [ax.get_ylim()[0], yp], color=COLOR_PEAK, lw=0.8, ls=":", zorder=3)

    title = step_title(step)
    fig.text(0.085, 0.955, title, fontsize=13, fontweight="bold", ha="left", va="center")
    sub = run_subtitle_parts(metrics)
    sub.append(f"step at t = {t_step:.2f} s")
    if step.get("passed") is not None:
        sub.append("criteria PASSED" if step["passed"] else "criteria FAILED")
    fig.text(0.085, 0.905, "  ·  ".join(sub), fontsize=8.5, color="0.3", ha="left", va="center")

    # Keep wide tick labels / axis labels inside the figure and clear of the right panel
    x_panel = 0.735
    _fit_twin_axes(fig, ax, ax2, left_min=0.012, right_max=x_panel - 0.015)

    # Right panel: legend, then the figures box below it
    leg = fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(x_panel - 0.008, 0.875),
                     fontsize=7.2, frameon=False, handlelength=2.2, borderaxespad=0.0,
                     labelspacing=0.45)
    fig.canvas.draw()
    bb = leg.get_window_extent(fig.canvas.get_renderer()).transformed(fig.transFigure.inverted())
    box_top = bb.y0 - 0.03

    fig.text(x_panel, box_top, _figures_text(step, has_metrics), family="DejaVu Sans Mono",
             fontsize=7.3, ha="left", va="top", linespacing=1.35,
             bbox=dict(boxstyle="round,pad=0.5", facecolor="#f7f7f7",
                       edgecolor=(COLOR_SETTLE if step.get("passed") else
                                  (COLOR_VAR if step.get("passed") is False else "0.6")),
                       lw=0.9))

    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def _figures_text(step, has_metrics):
    figs, ref = step["figures"], step["reference"]
    band = step.get("settling_band_pct", DEFAULT_SETTLING_BAND_PCT)
    if not has_metrics:
        return "no metrics.json:\nstep figures not available"
    keys = [k for k in FIGURE_ORDER if k in figs] + [k for k in figs if k not in FIGURE_INFO]
    ref_keys = [k for k in ref if k != "source"]
    keys += [k for k in FIGURE_ORDER if k in ref_keys and k not in keys]
    keys += [k for k in ref_keys if k not in keys]
    if not keys:
        return "no step figures in metrics.json"
    has_ref = bool(ref_keys)
    lw, cw = 10, 9
    lines = ["step figures".ljust(lw) + "run".rjust(cw) + ("paper".rjust(cw) if has_ref else "")]
    for k in keys:
        row = _figure_label(k, band)[:lw].ljust(lw) + _figure_cell(k, figs.get(k)).rjust(cw)
        if has_ref:
            row += (_figure_cell(k, ref[k]) if k in ref else "").rjust(cw)
        lines.append(row.rstrip())
    if ref.get("source"):
        src = textwrap.wrap(f"source: {ref['source']}", width=lw + 2 * cw,
                            subsequent_indent="  ", max_lines=3, placeholder=" …")
        lines.extend(src)
    crit = step["criteria"]
    if crit:
        judged = [c for c in crit if c.get("judged", True) is True]
        npass = sum(1 for c in judged if c.get("passed") is True)
        lines.append("")
        lines.append(f"judged {npass}/{len(judged)} passed" if judged else "not judged (figures only)")
        # Wrapped, not cut: "paper: overshoot in [15, 21]" is wider than the table's columns.
        for c in crit:
            lines.extend(textwrap.wrap(_criterion_line(c, band), width=lw + 2 * cw, subsequent_indent="    "))
    return "\n".join(lines)


# --------------------------------------------------------------------------- overview


def plot_overview(traj, out_path, metrics, run_dir):
    t = traj["t"]
    fig = plt.figure(figsize=OVERVIEW_FIGSIZE, dpi=DPI)
    gs = fig.add_gridspec(2, 3, left=0.05, right=0.985, bottom=0.065, top=0.885,
                          wspace=0.26, hspace=0.32)
    xyz_colors = ("#d62728", "#2ca02c", "#1f4fd6")
    leg_kw = dict(fontsize=8, loc="upper right", framealpha=0.85, ncol=2, handlelength=1.8,
                  columnspacing=1.0)

    # 1. 3D path
    ax3 = fig.add_subplot(gs[0, 0], projection="3d")
    x, y, z = traj["x"], traj["y"], traj["z"]
    xd, yd, zd = traj["x_des"], traj["y_des"], traj["z_des"]
    ax3.plot(x, y, z, color="#d62728", lw=1.4, label="path")
    ax3.plot(xd, yd, zd, color=COLOR_SETPOINT, lw=1.0, ls="--", label="setpoint")
    ax3.scatter([x[0]], [y[0]], [z[0]], color="k", marker="o", s=18, label="start", depthshade=False)
    ax3.scatter([x[-1]], [y[-1]], [z[-1]], color="#1f4fd6", marker="s", s=18, label="end",
                depthshade=False)
    _equal_axes_3d(ax3, (x, xd), (y, yd), (z, zd))
    ax3.set_xlabel("x [m]", fontsize=8, labelpad=-2)
    ax3.set_ylabel("y [m]", fontsize=8, labelpad=-2)
    ax3.set_zlabel("z [m]", fontsize=8, labelpad=-2)
    ax3.tick_params(labelsize=7, pad=-1)
    ax3.set_title("3D path (equal axes)", fontsize=10)
    ax3.legend(fontsize=7, loc="upper left", framealpha=0.85)

    def timeplot(ax, cols, labels, colors, ylabel, title, des_cols=None):
        handles = []
        for i, (c, lab, col) in enumerate(zip(cols, labels, colors)):
            h, = ax.plot(t, traj[c], color=col, lw=1.3, label=lab)
            handles.append(h)
            if des_cols:
                ax.plot(t, traj[des_cols[i]], color=col, lw=1.0, ls="--", alpha=0.8)
        if des_cols:
            handles.append(Line2D([], [], color=COLOR_SETPOINT, lw=1.0, ls="--", label="setpoint"))
        handles += shade_saturation(ax, traj)
        ax.set_xlabel("time t [s]", fontsize=9)
        ax.set_ylabel(ylabel, fontsize=9)
        ax.set_title(title, fontsize=10)
        ax.tick_params(labelsize=8)
        ax.grid(True, color="0.88", lw=0.6)
        if t[-1] > t[0]:
            ax.set_xlim(float(t[0]), float(t[-1]))
        lo_hi = _finite_minmax(*(traj[c] for c in cols + (tuple(des_cols) if des_cols else ())))
        if lo_hi is not None:
            lo, hi = lo_hi
            # A signal that varies by round-off only (vz ~1e-16 m/s in a yaw step) is drawn flat at
            # its value, not magnified into noise.
            if hi - lo < 1e-9 * max(1.0, abs(lo), abs(hi)):
                lo = hi = 0.5 * (lo + hi)
            pad = 0.08 * (hi - lo) if hi > lo else max(0.05, abs(hi) * 0.1)
            # headroom at the top for the legend
            ax.set_ylim(lo - pad, hi + pad + 0.3 * max(hi - lo, 2 * pad))
        ax.legend(handles=handles, **leg_kw)

    timeplot(fig.add_subplot(gs[0, 1]), ("x", "y", "z"), ("x", "y", "z"), xyz_colors,
             "position [m]", "Position (dashed: setpoint)", ("x_des", "y_des", "z_des"))
    timeplot(fig.add_subplot(gs[0, 2]), ("roll", "pitch", "yaw"), ("roll φ", "pitch θ", "yaw ψ"),
             xyz_colors, "attitude [rad]", "Attitude (dashed: setpoint)",
             ("roll_des", "pitch_des", "yaw_des"))
    timeplot(fig.add_subplot(gs[1, 0]), ("p", "q", "r"), ("p", "q", "r"), xyz_colors,
             "body rate [rad/s]", "Body rates")
    rotors = range(1, traj.rotor_count() + 1)
    timeplot(fig.add_subplot(gs[1, 1]), tuple(f"w{k}" for k in rotors), tuple(f"ω{k}" for k in rotors),
             ("#d62728", "#2ca02c", "#1f4fd6", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"),
             "rotor speed [rad/s]", "Rotor speeds")
    timeplot(fig.add_subplot(gs[1, 2]), ("vz",), ("vz",), ("#1f4fd6",),
             "vertical speed vz [m/s]", "Vertical speed")

    title = f"Run overview — {os.path.basename(os.path.abspath(run_dir))}"
    sub = [f"{len(t)} samples, t = {t[0]:.2f} … {t[-1]:.2f} s"]
    if metrics:
        sub = run_subtitle_parts(metrics) + sub
        if metrics.get("passed") is not None:
            sub.append("PASSED" if metrics["passed"] else "FAILED")
        # The file's description names the controller it was written for: not when another flew.
        if metrics.get("description") and not controller_replaced(metrics):
            d = metrics["description"]
            sub.append(d if len(d) <= 90 else d[:87] + "…")
    fig.text(0.05, 0.968, title, fontsize=14, fontweight="bold", ha="left", va="center")
    fig.text(0.05, 0.937, "  ·  ".join(sub), fontsize=9, color="0.3", ha="left", va="center")
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


# --------------------------------------------------------------------------- tracking

TRACKING_FIGURE_NAMES = ("tracking_path.png", "tracking_axes.png", "tracking_error.png")
TRACKING_FIGSIZE = (13.0, 5.5)
XYZ_COLORS = ("#d62728", "#2ca02c", "#1f4fd6")


def output_groups(names):
    """The panels of outputs.png: names sharing the part before their last dot ("e_x" of "e_x.x") share
    one, the others have their own; in the order the names first appear. [(title, [names])]."""
    groups = {}
    for name in names:
        prefix = name.rsplit(".", 1)[0] if "." in name else name
        if sum(1 for n in names if "." in n and n.rsplit(".", 1)[0] == prefix) < 2:
            prefix = name
        groups.setdefault(prefix, []).append(name)
    return list(groups.items())


def plot_outputs(traj, out_path, metrics):
    """The controller's declared figures against time, a panel per group (output_groups)."""
    t = traj["t"]
    groups = output_groups(traj.output_names())
    shown, left_out = groups[:MAX_OUTPUT_PANELS], groups[MAX_OUTPUT_PANELS:]
    ncols = 1 if len(shown) == 1 else 2 if len(shown) <= 4 else 3
    nrows = math.ceil(len(shown) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.0 * ncols, 2.6 * nrows + 0.9), squeeze=False, sharex=True)
    for ax, (title, names) in zip(axes.flat, shown):
        for name in names:
            label = name[len(title) + 1:] if name != title else name
            ax.plot(t, traj[OUTPUT_PREFIX + name], lw=1.2, label=label)
        ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        if len(names) > 1:
            ax.legend(fontsize=8, loc="best")
        shade_saturation(ax, traj)
    for ax in axes.flat[len(shown):]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    title = "The controller's own figures (trajectory.csv out.* columns)"
    if left_out:
        title += f"; not drawn: {', '.join(n for _, names in left_out for n in names)}"
    parts = run_subtitle_parts(metrics) if metrics is not None else []
    fig.suptitle(title + ("\n" + " · ".join(parts) if parts else ""), fontsize=11)
    fig.tight_layout()
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def _tracking_after_s(metrics):
    v = (metrics.get("tracking") or {}).get("after_s")
    return float(v) if _is_number(v) and math.isfinite(float(v)) else 0.0


def _tracking_subtitle(metrics):
    tr = metrics.get("tracking") or {}
    figs = tr.get("figures") or {}
    parts = run_subtitle_parts(metrics) + [f"judged from t = {_tracking_after_s(metrics):g} s"]
    if _is_number(figs.get("position_rmse_m")):
        parts.append(f"position RMSE {float(figs['position_rmse_m']):.4g} m")
    if _is_number(figs.get("position_max_m")):
        parts.append(f"max {float(figs['position_max_m']):.4g} m")
    if _is_number(figs.get("yaw_rmse_rad")):
        parts.append(f"yaw RMSE {float(figs['yaw_rmse_rad']):.4g} rad")
    if isinstance(tr.get("passed"), bool) and tr.get("criteria"):
        parts.append("PASSED" if tr["passed"] else "FAILED")
    return "  ·  ".join(parts)


def _mark_after(ax, t, after_s):
    """Greys the samples before after_s (not judged) and returns a legend handle, or [] when none."""
    if after_s <= float(t[0]):
        return []
    ax.axvspan(float(t[0]), min(after_s, float(t[-1])), color="0.88", lw=0, zorder=0)
    return [Patch(facecolor="0.88", label=f"not judged (t < {after_s:g} s)")]


def plot_tracking_path(traj, out_path, metrics):
    x, y, z = traj["x"], traj["y"], traj["z"]
    xd, yd, zd = traj["x_des"], traj["y_des"], traj["z_des"]
    fig = plt.figure(figsize=TRACKING_FIGSIZE, dpi=DPI)
    gs = fig.add_gridspec(1, 2, left=0.03, right=0.98, bottom=0.1, top=0.86, wspace=0.15)
    ax3 = fig.add_subplot(gs[0, 0], projection="3d")
    ax3.plot(xd, yd, zd, color=COLOR_SETPOINT, lw=1.2, ls="--", label="reference")
    ax3.plot(x, y, z, color=COLOR_VAR, lw=1.2, label="path")
    ax3.scatter([x[0]], [y[0]], [z[0]], color="k", marker="o", s=18, label="start", depthshade=False)
    _equal_axes_3d(ax3, (x, xd), (y, yd), (z, zd))
    ax3.set_xlabel("x [m]", fontsize=9)
    ax3.set_ylabel("y [m]", fontsize=9)
    ax3.set_zlabel("z [m]", fontsize=9)
    ax3.tick_params(labelsize=8)
    ax3.set_title("3D path (equal axes)", fontsize=11)
    ax3.legend(fontsize=8, loc="upper left", framealpha=0.85)

    ax = fig.add_subplot(gs[0, 1])
    ax.plot(xd, yd, color=COLOR_SETPOINT, lw=1.2, ls="--", label="reference")
    ax.plot(x, y, color=COLOR_VAR, lw=1.2, label="path")
    ax.plot([x[0]], [y[0]], "ko", ms=4, label="start")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]", fontsize=9)
    ax.set_ylabel("y [m]", fontsize=9)
    ax.set_title("Top view (x–y, equal axes)", fontsize=11)
    ax.tick_params(labelsize=8)
    ax.grid(True, color="0.88", lw=0.6)
    ax.legend(fontsize=8, loc="upper right", framealpha=0.85)
    fig.text(0.03, 0.955, "Trajectory tracking: path", fontsize=14, fontweight="bold", ha="left", va="center")
    fig.text(0.03, 0.915, _tracking_subtitle(metrics), fontsize=9, color="0.3", ha="left", va="center")
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def plot_tracking_axes(traj, out_path, metrics):
    t = traj["t"]
    after_s = _tracking_after_s(metrics)
    fig, axes = plt.subplots(3, 1, figsize=(10.0, 8.0), dpi=DPI, sharex=True)
    fig.subplots_adjust(left=0.09, right=0.97, bottom=0.07, top=0.89, hspace=0.12)
    for ax, ch, col in zip(axes, ("x", "y", "z"), XYZ_COLORS):
        h_ref, = ax.plot(t, traj[ch + "_des"], color=COLOR_SETPOINT, lw=1.2, ls="--", label=f"{ch} reference")
        h, = ax.plot(t, traj[ch], color=col, lw=1.2, label=ch)
        handles = [h, h_ref] + _mark_after(ax, t, after_s)
        ax.set_ylabel(f"{ch} [m]", fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(True, color="0.88", lw=0.6)
        ax.legend(handles=handles, fontsize=8, loc="upper right", framealpha=0.85)
    axes[-1].set_xlabel("time t [s]", fontsize=9)
    if t[-1] > t[0]:
        axes[-1].set_xlim(float(t[0]), float(t[-1]))
    fig.text(0.09, 0.96, "Trajectory tracking: position against the reference", fontsize=14,
             fontweight="bold", ha="left", va="center")
    fig.text(0.09, 0.925, _tracking_subtitle(metrics), fontsize=9, color="0.3", ha="left", va="center")
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def tracking_errors(traj, reference_period_s=0.0):
    """Errors as metrics.json's tracking figures define them, at the samples they count: "t" the
    samples at the multiples of reference_period_s (the controller's steps, where the recorded reference
    is current; every sample for 0), reference minus measured for x, y, z [m], their Euclidean norm
    "norm", and "psi" (None without an att_err column)."""
    t = traj["t"]
    keep = np.ones(len(t), dtype=bool)
    if reference_period_s > 0:
        k = t / reference_period_s
        keep = np.abs(k - np.round(k)) <= 1e-6
    e = {"t": t[keep]}
    e.update({ch: (traj[ch + "_des"] - traj[ch])[keep] for ch in ("x", "y", "z")})
    e["norm"] = np.sqrt(e["x"] ** 2 + e["y"] ** 2 + e["z"] ** 2)
    e["psi"] = traj["att_err"][keep] if traj.has("att_err") else None
    return e


def _reference_period_s(metrics):
    v = (metrics.get("tracking") or {}).get("reference_period_s")
    return float(v) if _is_number(v) and math.isfinite(float(v)) and float(v) > 0 else 0.0


def plot_tracking_error(traj, out_path, metrics):
    t = traj["t"]
    after_s = _tracking_after_s(metrics)
    e = tracking_errors(traj, _reference_period_s(metrics))
    te = e["t"]
    psi = e["psi"]
    has_psi = psi is not None and np.any(np.isfinite(psi))
    rows = 3 if has_psi else 2
    fig, axes = plt.subplots(rows, 1, figsize=(10.0, 2.7 * rows + 0.8), dpi=DPI, sharex=True)
    fig.subplots_adjust(left=0.09, right=0.97, bottom=0.07, top=1.0 - 0.75 / (2.7 * rows + 0.8), hspace=0.14)

    def finish(ax, handles, ylabel, values, from_zero=False):
        handles = handles + _mark_after(ax, t, after_s)
        ax.set_ylabel(ylabel, fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(True, color="0.88", lw=0.6)
        # Scaled to the judged interval: the start-up transient would hide the tracking error.
        judged = te >= after_s
        lo_hi = _finite_minmax(*(v[judged] for v in values)) if judged.any() else None
        if lo_hi is not None:
            lo, hi = lo_hi
            pad = 0.1 * (hi - lo) if hi > lo else max(1e-3, abs(hi) * 0.1)
            lo = 0.0 if from_zero else lo - pad
            ax.set_ylim(lo, hi + pad + 0.35 * max(hi - lo, 2 * pad))
        ax.legend(handles=handles, fontsize=8, loc="upper right", framealpha=0.85, ncol=len(handles))

    h, = axes[0].plot(te, e["norm"], color="k", lw=1.2, label="|e| (3D)")
    finish(axes[0], [h], "position error |e| [m]", [e["norm"]], from_zero=True)
    hs = [axes[1].plot(te, e[ch], color=col, lw=1.2, label=f"e_{ch}")[0] for ch, col in zip(("x", "y", "z"), XYZ_COLORS)]
    axes[1].axhline(0.0, color="0.5", lw=0.8)
    finish(axes[1], hs, "error per axis [m]", [e["x"], e["y"], e["z"]])
    if has_psi:
        h, = axes[2].plot(te, psi, color="#8c564b", lw=1.2, label="Ψ = ½ tr(I − R_dᵀR)")
        finish(axes[2], [h], "attitude error Ψ [-]", [psi], from_zero=True)
    axes[-1].set_xlabel("time t [s]", fontsize=9)
    if t[-1] > t[0]:
        axes[-1].set_xlim(float(t[0]), float(t[-1]))
    top = 1.0 - 0.75 / (2.7 * rows + 0.8)
    fig.text(0.09, top + (1 - top) * 0.7, "Trajectory tracking: error (reference − measured, at the controller's steps)",
             fontsize=14, fontweight="bold", ha="left", va="center")
    fig.text(0.09, top + (1 - top) * 0.3, _tracking_subtitle(metrics), fontsize=9, color="0.3", ha="left",
             va="center")
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


# --------------------------------------------------------------------------- main


def _settle_estimate(t, y, t_step, target, half_band, t_hi):
    """Rough settling time in target +- half_band (for choosing the plot window only)."""
    m = (t >= t_step) & (t <= t_hi)
    if not m.any():
        return 0.0
    outside = np.nonzero(~(np.abs(y[m] - target) <= (half_band or 0.02)))[0]
    if outside.size == 0:
        return 0.0
    return float(t[m][outside[-1]] - t_step)


def step_figure_names(steps):
    """The file name of each step's figure: step_<channel>.png, then step_<channel>_2.png, ..."""
    names, counts = [], {}
    for step in steps:
        ch = step["channel"]
        counts[ch] = counts.get(ch, 0) + 1
        names.append(f"step_{ch}.png" if counts[ch] == 1 else f"step_{ch}_{counts[ch]}.png")
    return names


def step_windows(steps, traj):
    """Time window [lo, hi] per step. It ends at the next step of the same
    channel (or the end of the run), and in long runs is cut to
    max(15 s, 2.5 x settling time) after the step, so the response stays
    readable; a short lead-in before the step is kept."""
    t = traj["t"]
    t0, t1 = float(t[0]), float(t[-1])
    windows = []
    for i, s in enumerate(steps):
        ts = s["t_step_s"]
        same = [o["t_step_s"] for j, o in enumerate(steps)
                if j != i and o["channel"] == s["channel"]]
        hi_lim = min([v for v in same if v > ts], default=t1)
        settle = s["figures"].get("settling_time_2pct_s")
        if settle is None:
            on_trace = step_on_trace(traj, s)
            settle = _settle_estimate(t, traj[s["channel"]], ts, on_trace["target"], on_trace["half_band"], hi_lim)
        hi = min(hi_lim, ts + max(15.0, 2.5 * settle))
        if hi_lim - hi < 0.25 * (hi - ts):  # not worth cutting
            hi = hi_lim
        lo_lim = max([v for v in same if v < ts], default=t0)
        pre = 0.1 * (hi - ts)
        lo = lo_lim if ts - lo_lim <= 2.0 * pre else ts - pre
        windows.append((lo, hi))
    return windows


def run(run_dir):
    if not os.path.isdir(run_dir):
        raise InputError(f"{run_dir}: run directory not found")
    traj = load_trajectory(os.path.join(run_dir, "trajectory.csv"))
    metrics_path = os.path.join(run_dir, "metrics.json")
    metrics = load_metrics(metrics_path)
    if metrics is not None:
        steps = metrics["steps"]
        if not steps:
            print(f"{PROG}: note: {metrics_path} lists no steps; no step plots", file=sys.stderr)
    else:
        steps = detect_steps(traj)
        if not steps:
            print(f"{PROG}: note: no metrics.json and no setpoint changes; no step plots",
                  file=sys.stderr)

    written = []
    for step, window, name in zip(steps, step_windows(steps, traj), step_figure_names(steps)):
        out = os.path.join(run_dir, name)
        plot_step(traj, step, window, out, metrics, metrics is not None)
        written.append(out)
        print(out, flush=True)

    out = os.path.join(run_dir, "overview.png")
    plot_overview(traj, out, metrics, run_dir)
    written.append(out)
    print(out, flush=True)

    if traj.output_names():
        out = os.path.join(run_dir, "outputs.png")
        plot_outputs(traj, out, metrics)
        written.append(out)
        print(out, flush=True)

    if metrics is not None and metrics.get("tracking") is not None:
        for name, plot in zip(TRACKING_FIGURE_NAMES, (plot_tracking_path, plot_tracking_axes, plot_tracking_error)):
            out = os.path.join(run_dir, name)
            plot(traj, out, metrics)
            written.append(out)
            print(out, flush=True)
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Plot RUN_DIR/trajectory.csv (+ metrics.json) into PNGs in RUN_DIR.")
    parser.add_argument("run_dir", metavar="RUN_DIR", help="directory holding trajectory.csv")
    args = parser.parse_args(argv)
    try:
        run(args.run_dir)
    except InputError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:  # e.g. RUN_DIR not writable
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
