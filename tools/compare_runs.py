#!/usr/bin/python3
"""Compare two quadcosim run directories.

Usage: compare_runs.py RUN_A RUN_B [--out DIR]

For each channel stepped in either run (the steps of metrics.json, or, without
metrics.json, the setpoint changes found in trajectory.csv), writes
DIR/compare_<channel>.png: the variable against time, run A solid, run B
dashed, the setpoints grey. When either run tracked a trajectory (metrics.json
has "tracking"), writes DIR/compare_tracking_path.png (both paths over their
references, top view x-y) and DIR/compare_tracking_error.png (the error
reference - measured of both runs over time: norm, x, y, z). Prints a Markdown
table of the tracking and step figures side by side (figure, A, B, difference
B - A) to stdout and writes it to DIR/compare.md. Steps are paired by channel
and order of occurrence. Runs are labelled by folder name and the controller
that flew (metrics.json "provenance").

DIR defaults to RUN_B/compare_with_<name of RUN_A>. Loading helpers come from
plot_run.py (imported as a module). Exit status: 0 on success, 1 when an input
file is missing or malformed (the message names the file), 2 on a usage error.
"""

import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import plot_run  # noqa: E402  (sets the Agg backend)
from plot_run import InputError  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

PROG = "compare_runs.py"
COLOR_A = "#d62728"
COLOR_B = "#1f4fd6"


def load_run(run_dir):
    if not os.path.isdir(run_dir):
        raise InputError(f"{run_dir}: run directory not found")
    traj = plot_run.load_trajectory(os.path.join(run_dir, "trajectory.csv"))
    metrics = plot_run.load_metrics(os.path.join(run_dir, "metrics.json"))
    steps = metrics["steps"] if metrics is not None else plot_run.detect_steps(traj)
    return traj, metrics, steps


def run_label(run_dir, metrics):
    """The run folder's name and, in parentheses, the controller that flew (metrics.json provenance)
    and the scenario when its name differs from the folder's: "a (example_pd, circle_se3)"."""
    name = os.path.basename(os.path.normpath(os.path.abspath(run_dir)))
    extra = []
    label = plot_run.controller_label(metrics)
    if label:
        extra.append(label)
    if metrics and metrics.get("scenario") and metrics["scenario"] != name:
        extra.append(metrics["scenario"])
    return f"{name} ({', '.join(extra)})" if extra else name


def is_tracking(metrics):
    return bool(metrics and metrics.get("tracking"))


def plot_tracking_path(traj_a, traj_b, label_a, label_b, out_path):
    """Top view x-y of both runs over their references (equal axes)."""
    fig, ax = plt.subplots(figsize=(8.0, 7.0), dpi=plot_run.DPI)
    ax.plot(traj_a["x_des"], traj_a["y_des"], color=plot_run.COLOR_SETPOINT, lw=1.0, ls="-", alpha=0.7,
            label="reference A")
    ax.plot(traj_b["x_des"], traj_b["y_des"], color=plot_run.COLOR_SETPOINT, lw=1.0, ls=":", alpha=0.9,
            label="reference B")
    ax.plot(traj_a["x"], traj_a["y"], color=COLOR_A, lw=1.4, ls="-", label=f"A: {label_a}")
    ax.plot(traj_b["x"], traj_b["y"], color=COLOR_B, lw=1.4, ls="--", label=f"B: {label_b}")
    ax.plot([traj_a["x"][0]], [traj_a["y"][0]], "o", color=COLOR_A, ms=4)
    ax.plot([traj_b["x"][0]], [traj_b["y"][0]], "s", color=COLOR_B, ms=4, mfc="none")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Tracking path, top view (x–y): A (solid) vs B (dashed)", fontsize=12, fontweight="bold")
    ax.grid(True, color="0.88", lw=0.6)
    ax.legend(fontsize=8, loc="best", framealpha=0.85)
    fig.tight_layout()
    fig.savefig(out_path, dpi=plot_run.DPI)
    plt.close(fig)


def plot_tracking_error(traj_a, traj_b, metrics_a, metrics_b, label_a, label_b, out_path):
    """The tracking error (reference − measured) of both runs over time, at the samples each run's
    tracking figures count: its norm, then each axis. Axes scaled to the judged samples."""
    ea = plot_run.tracking_errors(traj_a, plot_run._reference_period_s(metrics_a or {}))
    eb = plot_run.tracking_errors(traj_b, plot_run._reference_period_s(metrics_b or {}))
    after_a = plot_run._tracking_after_s(metrics_a or {})
    after_b = plot_run._tracking_after_s(metrics_b or {})
    fig, axes = plt.subplots(4, 1, figsize=(10.0, 10.0), dpi=plot_run.DPI, sharex=True)
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.06, top=0.93, hspace=0.12)
    rows = (("norm", "|e| (3D) [m]"), ("x", "e_x [m]"), ("y", "e_y [m]"), ("z", "e_z [m]"))
    for ax, (key, ylabel) in zip(axes, rows):
        ax.plot(ea["t"], ea[key], color=COLOR_A, lw=1.2, ls="-", label=f"A: {label_a}")
        ax.plot(eb["t"], eb[key], color=COLOR_B, lw=1.2, ls="--", label=f"B: {label_b}")
        if key != "norm":
            ax.axhline(0.0, color="0.5", lw=0.8)
        judged = [ea[key][ea["t"] >= after_a], eb[key][eb["t"] >= after_b]]
        lo_hi = plot_run._finite_minmax(*judged) if any(len(v) for v in judged) else None
        peaks = [float(np.nanmax(v)) for v in judged if len(v) and np.any(np.isfinite(v))]
        if key == "norm" and len(peaks) == 2 and min(peaks) > 0 and max(peaks) > 20 * min(peaks):
            # Errors an order of magnitude or more apart: on a log axis both stay readable.
            ax.set_yscale("log")
            floor = min(float(np.nanmin(v[v > 0])) for v in judged if np.any(v > 0))
            ax.set_ylim(floor / 2, max(peaks) * 30)  # room for the legend above the curves
            ax.set_ylabel("|e| (3D) [m], log", fontsize=9)
        elif lo_hi is not None:
            lo, hi = lo_hi
            pad = 0.1 * (hi - lo) if hi > lo else max(1e-4, abs(hi) * 0.1)
            ax.set_ylim(0.0 if key == "norm" else lo - pad, hi + pad + 0.3 * max(hi - lo, 2 * pad))
        after = min(after_a, after_b)
        t0 = min(float(ea["t"][0]), float(eb["t"][0])) if len(ea["t"]) and len(eb["t"]) else 0.0
        if after > t0:
            ax.axvspan(t0, after, color="0.88", lw=0, zorder=0)
        if ax.get_yscale() != "log":
            ax.set_ylabel(ylabel, fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(True, color="0.88", lw=0.6)
    axes[0].legend(fontsize=8, loc="upper right", framealpha=0.85)
    axes[-1].set_xlabel("time t [s]", fontsize=9)
    t_hi = max(float(traj_a["t"][-1]), float(traj_b["t"][-1]))
    t_lo = min(float(traj_a["t"][0]), float(traj_b["t"][0]))
    if t_hi > t_lo:
        axes[-1].set_xlim(t_lo, t_hi)
    fig.suptitle("Tracking error (reference − measured, at the controller's steps): A (solid) vs B (dashed); "
                 "grey: not judged", fontsize=11, fontweight="bold")
    fig.savefig(out_path, dpi=plot_run.DPI)
    plt.close(fig)


def tracking_table(metrics_a, metrics_b):
    """Markdown lines: the tracking figures of both runs side by side ([] when neither tracked)."""
    ta = (metrics_a or {}).get("tracking") or {}
    tb = (metrics_b or {}).get("tracking") or {}
    if not ta and not tb:
        return []
    fa, fb = ta.get("figures") or {}, tb.get("figures") or {}
    after = [f"{float(t['after_s']):g} s" if plot_run._is_number(t.get("after_s")) else "—" for t in (ta, tb)]
    lines = ["## Trajectory tracking", "",
             f"judged from t = {after[0]} (A), {after[1]} (B)", "",
             "| figure | A | B | difference (B − A) |", "|---|---:|---:|---:|"]
    order = ["position_rmse_m", "position_max_m", "x_rmse_m", "x_max_m", "y_rmse_m", "y_max_m", "z_rmse_m",
             "z_max_m", "yaw_rmse_rad", "attitude_error_rmse", "attitude_error_max"]
    keys = [k for k in order if k in fa or k in fb]
    keys += [k for k in list(fa) + list(fb) if k not in keys]
    keys = list(dict.fromkeys(keys))
    for k in keys:
        a, b = fa.get(k), fb.get(k)
        cell = (lambda v: "—" if not plot_run._is_number(v) else f"{float(v):.4g}")
        if plot_run._is_number(a) and plot_run._is_number(b):
            d = float(b) - float(a)
            diff = f"{d:+.4g}"
        else:
            diff = "—"
        lines.append(f"| {k} | {cell(a)} | {cell(b)} | {diff} |")
    lines.append("")
    return lines


def channels_of(*step_lists):
    stepped = {s["channel"] for steps in step_lists for s in steps}
    return [ch for ch in plot_run.CHANNEL_ORDER if ch in stepped]


def plot_channel(ch, traj_a, traj_b, label_a, label_b, out_path):
    meta = plot_run.CHANNELS[ch]
    fig, ax = plt.subplots(figsize=plot_run.STEP_FIGSIZE, dpi=plot_run.DPI)
    ax.plot(traj_a["t"], traj_a[f"{ch}_des"], color=plot_run.COLOR_SETPOINT, lw=1.0, ls="-",
            alpha=0.7, label="setpoint A")
    ax.plot(traj_b["t"], traj_b[f"{ch}_des"], color=plot_run.COLOR_SETPOINT, lw=1.0, ls="--",
            alpha=0.7, label="setpoint B")
    ax.plot(traj_a["t"], traj_a[ch], color=COLOR_A, lw=1.5, ls="-", label=f"A: {label_a}")
    ax.plot(traj_b["t"], traj_b[ch], color=COLOR_B, lw=1.5, ls="--", label=f"B: {label_b}")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"{meta['sym']} [{meta['unit']}]")
    ax.set_title(f"{meta['name']}: A (solid) vs B (dashed)", fontsize=12, fontweight="bold")
    ax.grid(True, color="0.88", lw=0.6)
    t_lo = min(float(np.nanmin(traj_a["t"])), float(np.nanmin(traj_b["t"])))
    t_hi = max(float(np.nanmax(traj_a["t"])), float(np.nanmax(traj_b["t"])))
    if t_hi > t_lo:
        ax.set_xlim(t_lo, t_hi)
    ax.legend(fontsize=8, loc="best", framealpha=0.85)
    fig.tight_layout()
    fig.savefig(out_path, dpi=plot_run.DPI)
    plt.close(fig)


def _pair_steps(steps_a, steps_b):
    """[(title, step_a or None, step_b or None)] paired by channel and occurrence."""
    def numbered(steps):
        counts, out = {}, {}
        for s in steps:
            counts[s["channel"]] = counts.get(s["channel"], 0) + 1
            out[(s["channel"], counts[s["channel"]])] = s
        return out
    na, nb = numbered(steps_a), numbered(steps_b)
    keys = sorted(set(na) | set(nb), key=lambda k: (plot_run.CHANNEL_ORDER.index(k[0]), k[1]))
    pairs = []
    for ch, n in keys:
        title = plot_run.CHANNELS[ch]["name"] + " step" + (f" #{n}" if n > 1 else "")
        pairs.append((title, na.get((ch, n)), nb.get((ch, n))))
    return pairs


def _diff_cell(key, a, b):
    if a is None or b is None:
        return "—"
    d = b - a
    _, unit, fmt = plot_run.FIGURE_INFO.get(key, (None, plot_run._unit_from_key(key), "{:.4g}"))
    s = fmt.format(d)
    if s.lstrip("-").strip("0.") == "":
        s = s.lstrip("-")  # rounds to zero: no sign
    elif not s.startswith("-"):
        s = "+" + s
    return f"{s} {unit}".strip()


def markdown_table(steps_a, steps_b, label_a, label_b, metrics_a=None, metrics_b=None):
    lines = [f"# Run figures: A = {label_a}, B = {label_b}", ""]
    lines += tracking_table(metrics_a, metrics_b)
    pairs = _pair_steps(steps_a, steps_b)
    if not pairs:
        if not (is_tracking(metrics_a) or is_tracking(metrics_b)):
            lines.append("No steps in either run.")
        return "\n".join(lines) + "\n"
    for title, sa, sb in pairs:
        fa = sa["figures"] if sa else {}
        fb = sb["figures"] if sb else {}
        keys = [k for k in plot_run.FIGURE_ORDER if k in fa or k in fb]
        for k in list(fa) + list(fb):
            if k not in keys:
                keys.append(k)
        lines.append(f"## {title}")
        lines.append("")
        if sa is None or sb is None:
            lines.append(f"(only in run {'A' if sb is None else 'B'})")
            lines.append("")
        if not keys:
            lines.append("No step figures (no metrics.json).")
            lines.append("")
            continue
        lines.append("| figure | A | B | difference (B − A) |")
        lines.append("|---|---:|---:|---:|")
        # The settling band of each run's step: "settle 2%", or "settle 2%/5%" when they differ.
        bands = [s.get("settling_band_pct", plot_run.DEFAULT_SETTLING_BAND_PCT) for s in (sa, sb) if s]
        for k in keys:
            a, b = fa.get(k), fb.get(k)
            label = plot_run._figure_label(k, bands[0])
            if k == "settling_time_2pct_s" and len(set(bands)) > 1:
                label += f"/{bands[1]:g}%"
            lines.append(f"| {label} | "
                         f"{plot_run._figure_cell(k, a) if sa else '—'} | "
                         f"{plot_run._figure_cell(k, b) if sb else '—'} | {_diff_cell(k, a, b)} |")
        lines.append("")
    return "\n".join(lines)


def run(run_a, run_b, out_dir=None):
    traj_a, metrics_a, steps_a = load_run(run_a)
    traj_b, metrics_b, steps_b = load_run(run_b)
    if out_dir is None:
        name_a = os.path.basename(os.path.normpath(os.path.abspath(run_a)))
        out_dir = os.path.join(run_b, f"compare_with_{name_a}")
    os.makedirs(out_dir, exist_ok=True)
    label_a, label_b = run_label(run_a, metrics_a), run_label(run_b, metrics_b)

    written = []
    for ch in channels_of(steps_a, steps_b):
        out = os.path.join(out_dir, f"compare_{ch}.png")
        plot_channel(ch, traj_a, traj_b, label_a, label_b, out)
        written.append(out)

    if is_tracking(metrics_a) or is_tracking(metrics_b):
        out = os.path.join(out_dir, "compare_tracking_path.png")
        plot_tracking_path(traj_a, traj_b, label_a, label_b, out)
        written.append(out)
        out = os.path.join(out_dir, "compare_tracking_error.png")
        plot_tracking_error(traj_a, traj_b, metrics_a, metrics_b, label_a, label_b, out)
        written.append(out)

    table = markdown_table(steps_a, steps_b, label_a, label_b, metrics_a, metrics_b)
    md = os.path.join(out_dir, "compare.md")
    with open(md, "w", encoding="utf-8", newline="\n") as f:
        f.write(table)
    written.append(md)
    sys.stdout.write(table)
    sys.stdout.flush()
    for p in written:
        print(f"{PROG}: wrote {p}", file=sys.stderr)
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog=PROG, description="Overlay two run directories and tabulate their step figures.")
    parser.add_argument("run_a", metavar="RUN_A", help="first run directory (solid lines)")
    parser.add_argument("run_b", metavar="RUN_B", help="second run directory (dashed lines)")
    parser.add_argument("--out", metavar="DIR", default=None,
                        help="output directory (default RUN_B/compare_with_<name of RUN_A>)")
    args = parser.parse_args(argv)
    try:
        run(args.run_a, args.run_b, args.out)
    except (InputError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
