#!/usr/bin/python3
"""Bode and Nyquist plots of `quadcosim margins --out DIR`.

Usage: plot_margins.py DIR

Reads DIR/frequency_response.csv (loop, omega_rad_s, re, im, magnitude_db,
phase_deg) and DIR/margins.json, and writes, printing each path:

  bode_<loop>.png     |L| [dB] and phase [deg] of the loop transfer against
                      frequency [rad/s], the gain crossover (PM) and phase
                      crossover (GM) marked, the Nyquist frequency dashed.
  nyquist_<loop>.png  L in the complex plane (positive frequencies; the
                      mirror image for negative ones dotted), the critical
                      point -1, the unit circle, and the margins in a box.

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
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            d = loops.setdefault(row["loop"], {"w": [], "re": [], "im": [], "db": [], "ph": []})
            d["w"].append(float(row["omega_rad_s"]))
            d["re"].append(float(row["re"]))
            d["im"].append(float(row["im"]))
            d["db"].append(float(row["magnitude_db"]))
            d["ph"].append(float(row["phase_deg"]))
    return {k: {kk: np.array(vv) for kk, vv in v.items()} for k, v in loops.items()}


def margin_text(loop):
    def fmt(m, key, unit, scale=1.0, digits=2):
        if m["status"] == "finite":
            return f"{m[key] * scale:.{digits}f} {unit} at {m['frequency_rad_s']:.3g} rad/s"
        return m["status"]

    lines = [
        f"GM  {fmt(loop['gain_margin'], 'db', 'dB')}",
        f"PM  {fmt(loop['phase_margin'], 'deg', 'deg', digits=1)}",
    ]
    dm = loop["delay_margin"]
    if dm["status"] == "finite":
        lines.append(f"DM  {dm['s']:.3f} s = {dm['samples']:.1f} samples")
    else:
        lines.append(f"DM  {dm['status']}")
    if not loop["closed_loop_stable"]:
        lines.append("closed loop UNSTABLE")
    if loop["open_loop_unstable_poles"]:
        lines.append(f"open loop unstable ({loop['open_loop_unstable_poles']} poles)")
    return "\n".join(lines)


def bode(name, d, loop, nyquist_w, out):
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    pm, gm = loop["phase_margin"], loop["gain_margin"]
    # The phase is unwrapped; shift it by whole turns so that it lies in (-360, 0] at the gain
    # crossover (or at the highest frequency), where -180 deg is the line that matters.
    ph = d["ph"]
    ref = np.interp(pm["frequency_rad_s"], d["w"], ph) if pm["status"] == "finite" else ph[-1]
    ph = ph - 360.0 * math.ceil(ref / 360.0)
    ax1.semilogx(d["w"], d["db"], color="tab:blue")
    lo, hi = max(d["db"].min(), -80.0), min(d["db"].max(), 100.0)
    ax1.set_ylim(lo - 5, hi + 5)
    ax1.axhline(0.0, color="grey", lw=0.8)
    ax1.set_ylabel("|L| [dB]")
    ax2.semilogx(d["w"], ph, color="tab:red")
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
    ax1.set_title(f"{name}: loop broken at {loop['broken_at']}")
    ax1.text(0.01, 0.03, margin_text(loop), transform=ax1.transAxes, fontsize=8, va="bottom",
             bbox=dict(boxstyle="round", fc="white", alpha=0.85))
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def nyquist(name, d, loop, out):
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    re, im = d["re"], d["im"]
    # Near an integrator |L| grows without bound at low frequency: show the region around -1.
    span = 4.0
    keep = np.hypot(re, im) < 50
    ax.plot(re[keep], im[keep], color="tab:blue", label="L(e^{jwT}), w > 0")
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
    ax.text(0.02, 0.02, margin_text(loop), transform=ax.transAxes, fontsize=8, va="bottom",
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
    for p in (csv_path, json_path):
        if not os.path.isfile(p):
            print(f"error: {p} not found (expected the --out directory of `quadcosim margins`)", file=sys.stderr)
            return 2
    response = read_response(csv_path)
    with open(json_path) as f:
        doc = json.load(f)
    nyquist_w = math.pi / doc["controller_period_s"] if doc.get("controller_period_s") else None
    for loop in doc["loops"]:
        name = loop["name"]
        if name not in response:
            continue
        for kind, fn in (("bode", bode), ("nyquist", nyquist)):
            out = os.path.join(d, f"{kind}_{name}.png")
            if kind == "bode":
                fn(name, response[name], loop, nyquist_w, out)
            else:
                fn(name, response[name], loop, out)
            print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
