#!/usr/bin/python3
"""Plots of a quadcosim sweep directory.

Usage: plot_sweep.py SWEEP_DIR

Reads SWEEP_DIR/summary.json (written by `quadcosim sweep`) and writes
  SWEEP_DIR/hist_<figure>.png  a histogram of each figure over the runs, the
                               scenario's bounds on it (when it has them) as
                               red lines, the mean as a dashed line;
  SWEEP_DIR/box.png            one box plot per figure (median, quartiles,
                               whiskers at 1.5 IQR, outliers), each figure on
                               its own axis, since their units differ.
Figures no run produced are skipped. Exit status: 0 on success, 1 when
summary.json is missing or malformed (the message names the file).
"""

import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 110
SAVE = {"dpi": DPI, "metadata": {"Software": None}}  # no version stamp: same data, same bytes


class InputError(Exception):
    pass


def load(sweep_dir):
    path = os.path.join(sweep_dir, "summary.json")
    try:
        with open(path, encoding="utf-8") as f:
            summary = json.load(f)
    except FileNotFoundError:
        raise InputError(f"{path}: file not found")
    except json.JSONDecodeError as e:
        raise InputError(f"{path}: not JSON ({e})")
    for key in ("runs", "passed", "figures", "per_run"):
        if key not in summary:
            raise InputError(f"{path}: no '{key}'")
    return summary


def bounds_of(sweep_dir, summary, figure):
    """The [min, max] the scenario puts on a figure, from the first run's metrics.json."""
    path = os.path.join(sweep_dir, "runs", "0000", "metrics.json")
    try:
        with open(path, encoding="utf-8") as f:
            m = json.load(f)
    except (OSError, json.JSONDecodeError):
        return None, None
    group, _, name = figure.partition(".")
    blocks = []
    if group == "hold" and m.get("hold"):
        blocks = [m["hold"]]
    else:
        channel = group.split("#")[0]
        blocks = [s for s in m.get("steps", []) if s.get("channel") == channel][:1]
    for b in blocks:
        for c in b.get("criteria", []):
            if c.get("figure") == name:
                return c.get("min"), c.get("max")
    return None, None


def values_of(summary, figure):
    return [r["figures"][figure] for r in summary["per_run"]
            if r["figures"].get(figure) is not None]


def safe(name):
    return "".join(ch if ch.isalnum() or ch in "._-" else "_" for ch in name)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    sweep_dir = argv[1]
    try:
        summary = load(sweep_dir)
    except InputError as e:
        print(f"plot_sweep.py: error: {e}", file=sys.stderr)
        return 1
    figures = [f for f in summary["figures"] if values_of(summary, f)]
    title = (f"{summary.get('scenario', '')}: {summary['passed']} of {summary['runs']} runs passed, "
             f"seed {summary.get('seed')}")
    for fig_name in figures:
        vals = values_of(summary, fig_name)
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        bins = max(5, min(40, int(math.sqrt(len(vals))) * 2))
        ax.hist(vals, bins=bins, color="#1f4fd6", alpha=0.8)
        lo, hi = bounds_of(sweep_dir, summary, fig_name)
        for b in (lo, hi):
            if b is not None:
                ax.axvline(b, color="#d62728", linewidth=1.5)
        ax.axvline(summary["figures"][fig_name]["mean"], color="black", linestyle="--", linewidth=1)
        ax.set_xlabel(fig_name)
        ax.set_ylabel("runs")
        ax.set_title(title, fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(sweep_dir, f"hist_{safe(fig_name)}.png"), **SAVE)
        plt.close(fig)
    if figures:
        n = len(figures)
        cols = min(n, 4)
        rows = math.ceil(n / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(3.0 * cols, 3.2 * rows), squeeze=False)
        for ax, fig_name in zip(axes.flat, figures):
            ax.boxplot(values_of(summary, fig_name))
            ax.set_xticks([1], [fig_name], fontsize=7)
            lo, hi = bounds_of(sweep_dir, summary, fig_name)
            for b in (lo, hi):
                if b is not None:
                    ax.axhline(b, color="#d62728", linewidth=1.2)
        for ax in list(axes.flat)[n:]:
            ax.axis("off")
        fig.suptitle(title, fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(sweep_dir, "box.png"), **SAVE)
        plt.close(fig)
    print(f"wrote {len(figures)} histograms and box.png to {sweep_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
