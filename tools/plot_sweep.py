#!/usr/bin/python3
"""Plots of a quadcosim sweep directory.

Usage: plot_sweep.py SWEEP_DIR

Reads SWEEP_DIR/summary.json (written by `quadcosim sweep`) and writes
  SWEEP_DIR/hist_<figure>.png  a histogram of each figure over the runs, the
                               scenario's bounds on it (when it has them) as
                               red lines, the mean as a dashed line;
  SWEEP_DIR/box.png            one box plot per figure (median, quartiles,
                               whiskers at 1.5 IQR, outliers), each figure on
                               its own axis, since their units differ;
  SWEEP_DIR/scatter_<key>.png  for each varied key, every figure against the
                               key's value, one point per run, passing runs
                               green and failing ones red, the bounds in red;
  SWEEP_DIR/headline_<key>.png the same for the headline figures only (those
                               the scenario's criteria bound, see
                               headline_figures), the plots index.html shows;
  SWEEP_DIR/map_<figure>.png   for a sweep with exactly two grid keys, the mean
  SWEEP_DIR/map_pass.png       of each figure over each grid point's runs as a
                               coloured map, and the passing runs of each point
                               ("k/n" in each cell).
The figures are those of summary.json: "<channel>.<figure>" of each step,
"hold.<figure>", and "saturation.<figure>" (time with rotors clamped, per
rotor, tilt-limited, RMS of U1 - m g; bounded by the scenario's
analysis.limits). Figures no run produced are skipped. Exit status: 0 on
success, 1 when summary.json is missing or malformed (the message names the
file).
"""

import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from sweep_results import (InputError, headline_figures, load, safe, values_of,  # noqa: E402,F401
                           varied_keys)

DPI = 110
SAVE = {"dpi": DPI, "metadata": {"Software": None}}  # no version stamp: same data, same bytes





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
    if group in ("hold", "saturation"):  # the hold's criteria; the saturation's: analysis.limits
        blocks = [m[group]] if m.get(group) else []
    else:
        channel = group.split("#")[0]
        blocks = [s for s in m.get("steps", []) if s.get("channel") == channel][:1]
    for b in blocks:
        for c in b.get("criteria", []):
            if c.get("figure") == name:
                return c.get("min"), c.get("max")
    return None, None














def scatter(sweep_dir, summary, figures, key, title, prefix="scatter", what="figures"):
    """Every figure against one varied key's value: a point per run, pass green, fail red."""
    n = len(figures)
    if n == 0:
        return
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    runs = summary["per_run"]
    for ax, fig_name in zip(axes.flat, figures):
        for passed, colour, label in ((True, "#2ca02c", "pass"), (False, "#d62728", "fail")):
            pts = [(r["values"][key], r["figures"][fig_name]) for r in runs
                   if r.get("passed") == passed and key in r.get("values", {})
                   and r["figures"].get(fig_name) is not None]
            if pts:
                ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=12, color=colour, alpha=0.7,
                           label=f"{label} ({len(pts)} runs)")
        missing = sum(1 for r in runs if r["figures"].get(fig_name) is None)
        lo, hi = bounds_of(sweep_dir, summary, fig_name)
        for b in (lo, hi):
            if b is not None:
                ax.axhline(b, color="#d62728", linewidth=1.0, linestyle=":")
        ax.set_xlabel(key, fontsize=8)
        ax.set_ylabel(fig_name, fontsize=8)
        ax.tick_params(labelsize=7)
        if missing:
            ax.set_title(f"{missing} runs without this figure", fontsize=7)
        ax.legend(fontsize=7, loc="best")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle(f"{title}\n{what} against {key}", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(sweep_dir, f"{prefix}_{safe(key)}.png"), **SAVE)
    plt.close(fig)


def grid_maps(sweep_dir, summary, figures, grids, title):
    """Two grid keys: the mean of each figure over each point's runs, and pass counts, as maps."""
    kx, ky = grids[1]["keys"][0]["path"], grids[0]["keys"][0]["path"]
    xs, ys = grids[1]["values"], grids[0]["values"]
    cells = {}
    for r in summary["per_run"]:
        cells.setdefault((r["values"][kx], r["values"][ky]), []).append(r)
    written = 0
    for fig_name in figures + ["pass"]:
        grid, text = [], []
        for y in ys:
            row, trow = [], []
            for x in xs:
                rs = cells.get((x, y), [])
                if fig_name == "pass":
                    k = sum(1 for r in rs if r.get("passed"))
                    row.append(k / len(rs) if rs else float("nan"))
                    trow.append(f"{k}/{len(rs)}")
                else:
                    v = [r["figures"][fig_name] for r in rs if r["figures"].get(fig_name) is not None]
                    row.append(sum(v) / len(v) if v else float("nan"))
                    trow.append(f"{row[-1]:.3g}" + (f"\n{len(v)}/{len(rs)} runs" if len(v) != len(rs) else "")
                                if v else "none")
            grid.append(row)
            text.append(trow)
        fig, ax = plt.subplots(figsize=(1.2 * len(xs) + 3.0, 0.8 * len(ys) + 2.2))
        cmap = "RdYlGn" if fig_name == "pass" else "viridis"
        im = ax.imshow(grid, origin="lower", aspect="auto", cmap=cmap,
                       vmin=0.0 if fig_name == "pass" else None, vmax=1.0 if fig_name == "pass" else None)
        for i in range(len(ys)):
            for j in range(len(xs)):
                ax.text(j, i, text[i][j], ha="center", va="center", fontsize=7,
                        color="black" if fig_name == "pass" else "white")
        ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
        ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys], fontsize=7)
        ax.set_xlabel(kx, fontsize=8)
        ax.set_ylabel(ky, fontsize=8)
        bar = fig.colorbar(im, ax=ax)
        bar.set_label("fraction of runs passed" if fig_name == "pass" else f"mean {fig_name}", fontsize=8)
        ax.set_title(f"{title}\n" + ("runs passed per grid point" if fig_name == "pass"
                                     else f"{fig_name}, mean over each point's runs"), fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(sweep_dir, f"map_{safe(fig_name)}.png"), **SAVE)
        plt.close(fig)
        written += 1
    return written


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
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
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
    keys = varied_keys(summary)
    headline = [f for f in headline_figures(sweep_dir, summary) if f in figures]
    for key in keys:
        scatter(sweep_dir, summary, figures, key, title)
        scatter(sweep_dir, summary, headline, key, title, prefix="headline", what="the criteria's figures")
    grids = [v for v in summary.get("vary", []) if v.get("distribution") == "grid"]
    maps = 0
    if len(grids) == 2 and figures:
        maps = grid_maps(sweep_dir, summary, figures, grids, title)
    print(f"wrote {len(figures)} histograms, box.png, {len(keys)} scatter plots (and as many of the headline "
          f"figures) and {maps} maps to {sweep_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
