"""What tools/plot_sweep.py and tools/sweep_index.py read from a sweep directory.

summary.json, each run's metrics.json, the criteria of a metrics.json by the
channel names of summary.json's figures, and a sweep's headline figures (those
its criteria bound). No plotting library: index.html is made without one.
"""

import json
import os


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


def first_metrics(sweep_dir, summary):
    """The metrics.json of the first run that has one (the scenario's criteria), or None."""
    for r in summary["per_run"]:
        path = os.path.join(sweep_dir, "runs", f"{r['index']:04d}", "metrics.json")
        try:
            with open(path, encoding="utf-8") as f:
                return json.load(f)
        except (OSError, json.JSONDecodeError):
            continue
    return None


def criteria_sections(metrics):
    """(channel as summary.json names it, section) of each part of metrics.json with criteria:
    each step ("z", "z#2" for a channel's second step), then "hold", "saturation", "tracking", ..."""
    out, seen = [], {}
    for step in metrics.get("steps", []):
        ch = step.get("channel", "?")
        seen[ch] = seen.get(ch, 0) + 1
        out.append((ch if seen[ch] == 1 else f"{ch}#{seen[ch]}", step))
    for key in sorted(metrics):
        if key != "steps" and isinstance(metrics[key], dict) and isinstance(metrics[key].get("criteria"), list):
            out.append((key, metrics[key]))
    return out


def headline_figures(sweep_dir, summary):
    """The figures a sweep is judged by: those the scenario's criteria bound (in metrics.json's
    order), else the first four figures some run has (saturation's last)."""
    names = []
    m = first_metrics(sweep_dir, summary)
    if m:
        for ch, section in criteria_sections(m):
            for c in section.get("criteria", []):
                name = f"{ch}.{c.get('figure')}"
                if name in summary["figures"] and name not in names:
                    names.append(name)
    if not names:
        have = [f for f in summary["figures"] if values_of(summary, f)]
        names = ([f for f in have if not f.startswith("saturation.")] + [f for f in have if f.startswith("saturation.")])[:4]
    return names


def values_of(summary, figure):
    return [r["figures"][figure] for r in summary["per_run"]
            if r["figures"].get(figure) is not None]


def safe(name):
    return "".join(ch if ch.isalnum() or ch in "._-" else "_" for ch in name)


def varied_keys(summary):
    keys = []
    for v in summary.get("vary", []):
        for k in v.get("keys", []):
            keys.append(k["path"])
    return keys
