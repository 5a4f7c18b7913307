#!/usr/bin/python3
"""Bode and Nyquist plots of `quadcosim margins --out DIR`.

Usage: plot_margins.py DIR

Reads DIR/margins.json and DIR/frequency_response.csv (loop, omega_rad_s, re,
im, magnitude_db, phase_deg: the analytic response of the paper controller's
loops) and/or DIR/measured_response.csv (the same columns and `converged`: the
response measured in simulation), and writes, printing each path:

  bode_<loop>.png     |L| [dB] and phase [deg] of the loop transfer against
                      frequency [rad/s], the gain crossover (PM) and phase
                      crossover (GM) marked, the Nyquist frequency dashed.
  nyquist_<loop>.png  L in the complex plane (positive frequencies; the
                      mirror image for negative ones dotted), the critical
                      point -1, the unit circle, and the margins in a box.

With both responses the measured frequencies are drawn as markers over the
analytic curves (both margins boxed); with the measured one alone, the measured
frequencies joined by lines, with the measured margins.

Only the Python standard library, numpy and matplotlib (Debian packages).
Exit 0 on success, 2 when DIR lacks its inputs.
"""

import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_response(path):
    loops = {}
    if not os.path.isfile(path):
        return loops
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            d = loops.setdefault(row["loop"], {"w": [], "re": [], "im": [], "db": [], "ph": []})
            d["w"].append(float(row["omega_rad_s"]))
            d["re"].append(float(row["re"]))
            d["im"].append(float(row["im"]))
            d["db"].append(float(row["magnitude_db"]))
            d["ph"].append(float(row["phase_deg"]))
    return {k: {kk: np.array(vv) for kk, vv in v.items()} for k, v in loops.items()}


def margin_text(loop, title=None):
    def fmt(m, key, unit, scale=1.0, digits=2):
        if m["status"] == "finite":
            return f"{m[key] * scale:.{digits}f} {unit} at {m['frequency_rad_s']:.3g} rad/s"
        return m["status"]

    lines = [title] if title else []
    lines += [
        f"GM  {fmt(loop['gain_margin'], 'db', 'dB')}",
        f"PM  {fmt(loop['phase_margin'], 'deg', 'deg', digits=1)}",
    ]
    dm = loop["delay_margin"]
    if dm["status"] == "finite":
        lines.append(f"DM  {dm['s']:.3f} s = {dm['samples']:.1f} samples")
    else:
        lines.append(f"DM  {dm['status']}")
    if not loop.get("closed_loop_stable", True):
        lines.append("closed loop UNSTABLE")
    if not loop.get("stayed_in_hover", True):
        lines.append("LEFT HOVER: margins undefined")
    if loop.get("open_loop_unstable_poles"):
        lines.append(f"open loop unstable ({loop['open_loop_unstable_poles']} poles)")
    return "\n".join(lines)


def bode(name, d, loop, nyquist_w, out, measured=None, measured_loop=None):
    """d: the curve (analytic, or measured when alone); measured: measured points drawn over it."""
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    pm, gm = loop["phase_margin"], loop["gain_margin"]
    alone = measured_loop is None and "points" in loop
    # The phase is unwrapped; shift it by whole turns so that it lies in (-360, 0] at the gain
    # crossover (or at the highest frequency), where -180 deg is the line that matters.
    ph = d["ph"]
    ref = np.interp(pm["frequency_rad_s"], d["w"], ph) if pm["status"] == "finite" else ph[-1]
    shift = 360.0 * math.ceil(ref / 360.0)
    ph = ph - shift
    style = dict(marker="o", ms=3) if alone else {}
    ax1.semilogx(d["w"], d["db"], color="tab:blue", label="measured" if alone else "analytic", **style)
    lo, hi = max(d["db"].min(), -80.0), min(d["db"].max(), 100.0)
    ax1.set_ylim(lo - 5, hi + 5)
    ax1.axhline(0.0, color="grey", lw=0.8)
    ax1.set_ylabel("|L| [dB]")
    ax2.semilogx(d["w"], ph, color="tab:red", **style)
    if measured is not None:
        # The measured phase, shifted by whole turns to lie nearest the analytic curve.
        mph = measured["ph"] - 360.0 * np.round((measured["ph"] - np.interp(measured["w"], d["w"], ph)) / 360.0)
        ax1.semilogx(measured["w"], measured["db"], "o", ms=4, mfc="none", color="black", label="measured")
        ax2.semilogx(measured["w"], mph, "o", ms=4, mfc="none", color="black")
        ax1.legend(loc="upper center", fontsize=8)
    for k in range(-5, 3):
        if ph.min() - 10 <= -180 + 360 * k <= ph.max() + 10:
            ax2.axhline(-180 + 360 * k, color="grey", lw=0.8)
    ax2.set_ylabel("phase of L [deg]")
    ax2.set_xlabel("frequency [rad/s]")
    if pm["status"] == "finite":
        for ax in (ax1, ax2):
            ax.axvline(pm["frequency_rad_s"], color="tab:green", ls=":", lw=1)
        ax2.annotate(f"PM {pm['deg']:.1f} deg", (pm["frequency_rad_s"], ref - 360.0 * math.ceil(ref / 360.0)),
                     textcoords="offset points", xytext=(5, 5), color="tab:green")
    if gm["status"] == "finite" and gm["frequency_rad_s"] > 0:
        for ax in (ax1, ax2):
            ax.axvline(gm["frequency_rad_s"], color="tab:purple", ls=":", lw=1)
        ax1.annotate(f"GM {gm['db']:.1f} dB", (gm["frequency_rad_s"], -gm["db"]),
                     textcoords="offset points", xytext=(-80, 5), color="tab:purple")
    if nyquist_w:
        for ax in (ax1, ax2):
            ax.axvline(nyquist_w, color="black", ls="--", lw=0.8)
        ax1.annotate("Nyquist", (nyquist_w, ax1.get_ylim()[1]), textcoords="offset points",
                     xytext=(-48, -14), fontsize=8)
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    ax1.set_title(f"{name}: loop broken at {loop['broken_at']}" + (" (measured)" if alone else ""))
    text = margin_text(loop, "analytic" if measured_loop else None)
    if measured_loop:
        text += "\n" + margin_text(measured_loop, "measured")
    ax1.text(0.01, 0.03, text, transform=ax1.transAxes, fontsize=8, va="bottom",
             bbox=dict(boxstyle="round", fc="white", alpha=0.85))
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def nyquist(name, d, loop, out, measured=None, measured_loop=None):
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    re, im = d["re"], d["im"]
    alone = measured_loop is None and "points" in loop
    # Near an integrator |L| grows without bound at low frequency: show the region around -1.
    span = 4.0
    keep = np.hypot(re, im) < 50
    ax.plot(re[keep], im[keep], color="tab:blue", label="L(e^{jwT}), w > 0" + (", measured" if alone else ""),
            **(dict(marker="o", ms=3) if alone else {}))
    if measured is not None:
        mk = np.hypot(measured["re"], measured["im"]) < 50
        ax.plot(measured["re"][mk], measured["im"][mk], "o", ms=4, mfc="none", color="black", label="measured")
    ax.plot(re[keep], -im[keep], color="tab:blue", ls=":", lw=0.8, label="w < 0")
    t = np.linspace(0, 2 * math.pi, 400)
    ax.plot(np.cos(t), np.sin(t), color="grey", lw=0.8, label="|L| = 1")
    ax.plot([-1], [0], "x", color="red", ms=10, mew=2, label="-1")
    ax.axhline(0, color="grey", lw=0.5)
    ax.axvline(0, color="grey", lw=0.5)
    ax.set_xlim(-span, span)
    ax.set_ylim(-span, span)
    ax.set_aspect("equal")
    ax.set_xlabel("Re L")
    ax.set_ylabel("Im L")
    ax.set_title(f"{name}: Nyquist plot (broken at {loop['broken_at']})", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    text = margin_text(loop, "analytic" if measured_loop else None)
    if measured_loop:
        text += "\n" + margin_text(measured_loop, "measured")
    ax.text(0.02, 0.02, text, transform=ax.transAxes, fontsize=8, va="bottom",
            bbox=dict(boxstyle="round", fc="white", alpha=0.85))
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    d = argv[1]
    csv_path, json_path = os.path.join(d, "frequency_response.csv"), os.path.join(d, "margins.json")
    measured_path = os.path.join(d, "measured_response.csv")
    if not os.path.isfile(json_path) or not (os.path.isfile(csv_path) or os.path.isfile(measured_path)):
        print(f"error: {json_path} and {csv_path} or {measured_path} not found "
              "(expected the --out directory of `quadcosim margins`)", file=sys.stderr)
        return 2
    response = read_response(csv_path)
    measured = read_response(measured_path)
    with open(json_path) as f:
        doc = json.load(f)
    nyquist_w = math.pi / doc["controller_period_s"] if doc.get("controller_period_s") else None
    measured_loops = {loop["name"]: loop for loop in doc.get("measured", {}).get("loops", [])}
    analytic_loops = {loop["name"]: loop for loop in doc.get("loops", [])}
    for name in list(analytic_loops) + [n for n in measured_loops if n not in analytic_loops]:
        if name in analytic_loops and name in response:
            curve, loop = response[name], analytic_loops[name]
            extra, extra_loop = measured.get(name), measured_loops.get(name)
        elif name in measured_loops and name in measured:
            curve, loop, extra, extra_loop = measured[name], measured_loops[name], None, None
        else:
            continue
        for kind, fn in (("bode", bode), ("nyquist", nyquist)):
            out = os.path.join(d, f"{kind}_{name}.png")
            if kind == "bode":
                fn(name, curve, loop, nyquist_w, out, extra, extra_loop)
            else:
                fn(name, curve, loop, out, extra, extra_loop)
            print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
