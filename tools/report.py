#!/usr/bin/python3
"""Write a self-contained HTML report of a quadcosim run directory.

Usage: report.py RUN_DIR [--version-text TEXT]

Writes RUN_DIR/report.html: one page that opens offline (inline CSS, the PNGs
embedded as base64 data URIs, no external URL) with

  - the scenario name, the controller that flew (metrics.json "provenance")
    and the scenario's description (marked as the file's when another
    controller flew than the one it names),
  - a verdict banner (PASSED / FAILED against the set judged, or FIGURES
    ONLY) and the headline figure: the position tracking RMSE of a tracking
    run, else the first step's overshoot and settling time,
  - the provenance block: controller (with a Python class's module file and
    SHA-256, an FMU's path and SHA-256, the parameter values), transport,
    scenario file and its SHA-256, command line, version and git commit, host,
  - the headline section first: for a tracking run the tracking figures
    against their spec and paper bands with tracking_path.png,
    tracking_axes.png and tracking_error.png; for a step run, per analysed
    step a table of the step figures (our value, the spec band (the
    specification) and the paper band (the paper's controller's response),
    each with its check (ok/FAIL for the judged set, in/out for the other),
    and the reference value and its source when metrics.json has a
    "reference") with the step plots,
  - the hold and saturation tables, then overview.png (other PNGs in RUN_DIR
    are not this run's and are left out),
  - the scenario as flown (RUN_DIR/scenario.yaml) in a <pre>,
  - versions: quadcosim (the text given with --version-text, e.g. the output of
    `quadcosim --version`), Python, numpy, matplotlib.

No date is written, so the same inputs give a byte-identical file. The loading
helpers come from plot_run.py (imported as a module). Prints the path of the
report. Exit status: 0 on success, 1 when metrics.json (required) or another
input is missing or malformed (the message names the file), 2 on a usage error.
"""

import argparse
import base64
import html
import os
import platform
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import plot_run  # noqa: E402  (sets the Agg backend)
from plot_run import InputError  # noqa: E402

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402

PROG = "report.py"

CSS = """
body { font-family: "DejaVu Sans", Arial, Helvetica, sans-serif; margin: 24px auto;
       max-width: 1150px; color: #222; line-height: 1.4; }
h1 { margin-bottom: 0.2em; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
.description { color: #555; margin-top: 0; }
.verdict { font-size: 1.6em; font-weight: bold; padding: 0.5em 0.8em; border-radius: 6px;
           margin: 0.8em 0; color: #fff; }
.verdict.passed { background: #2a7f2a; }
.verdict.failed { background: #c62828; }
.verdict.none { background: #777; }
table { border-collapse: collapse; margin: 0.5em 0 0.3em 0; }
th, td { border: 1px solid #bbb; padding: 4px 10px; text-align: left; }
th { background: #eee; }
td.num { text-align: right; font-family: "DejaVu Sans Mono", monospace; }
td.ok { color: #2a7f2a; font-weight: bold; }
td.fail { color: #c62828; font-weight: bold; }
.source { color: #555; font-size: 0.9em; margin-top: 0; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #555; font-size: 0.9em; }
pre { background: #f6f6f6; border: 1px solid #ddd; padding: 10px; overflow-x: auto;
      font-size: 0.85em; }
.versions td { font-family: "DejaVu Sans Mono", monospace; }
.flown { margin: 0.2em 0; }
.headline { font-size: 1.3em; font-weight: bold; margin: 0.4em 0 0.8em 0; }
.provenance td { font-family: "DejaVu Sans Mono", monospace; font-size: 0.85em; word-break: break-all; }
"""


def esc(s):
    return html.escape(str(s), quote=True)


def _band(c):
    lo, hi = c.get("min"), c.get("max")
    lo = lo if plot_run._is_number(lo) else None
    hi = hi if plot_run._is_number(hi) else None
    if lo is not None and hi is not None:
        return f"[{lo:g}, {hi:g}]"
    if lo is not None:
        return f"≥ {lo:g}"
    if hi is not None:
        return f"≤ {hi:g}"
    return "—"


SETS = ("spec", "paper")
SET_HEADERS = "<th>spec</th><th>check</th><th>paper</th><th>check</th>"


def _by_set(criteria):
    """{set: {figure: criterion}}; a criterion written before the sets existed is a spec."""
    out = {s: {} for s in SETS}
    for c in criteria:
        if isinstance(c, dict):
            out.setdefault(str(c.get("set", "spec")), {}).setdefault(str(c.get("figure", "?")), c)
    return out


def _check(c):
    """The check of one criterion: ok/FAIL when judged, in/out for a band shown but not judged."""
    if c is None:
        return "—", ""
    p = c.get("passed")
    if c.get("judged", True) is True:
        return _band(c), ("ok" if p is True else ("FAIL" if p is False else "?"))
    return _band(c), ("in" if p is True else ("out" if p is False else "?"))


def _set_cells(by_set, key):
    cells = ""
    for s in SETS:
        band, status = _check(by_set.get(s, {}).get(key))
        cls = ' class="ok"' if status == "ok" else (' class="fail"' if status == "FAIL" else "")
        cells += f"<td class=\"num\">{esc(band)}</td><td{cls}>{esc(status)}</td>"
    return cells


def figure_table(w, section, show):
    """Writes a section's figures (hold, saturation, tracking) as a table against its spec and paper
    bands; show(key, value) gives the value as text with its unit."""
    by_set = _by_set(section.get("criteria", []))
    w("<table>")
    w(f"<tr><th>figure</th><th>ours</th>{SET_HEADERS}</tr>")
    for key, value in (section.get("figures") or {}).items():
        ours = "—" if not plot_run._is_number(value) else show(key, float(value))
        w(f"<tr><td>{esc(key)}</td><td class=\"num\">{esc(ours)}</td>{_set_cells(by_set, key)}</tr>")
    w("</table>")


def step_rows(step):
    """Rows (figure key, ours, set cells, reference) of one step's table."""
    figs, ref = step["figures"], step["reference"]
    by_set = _by_set(step["criteria"])
    crit = {}
    for c in step["criteria"]:
        crit.setdefault(str(c.get("figure", "?")), c)
    keys = [k for k in plot_run.FIGURE_ORDER if k in figs]
    keys += [k for k in figs if k not in keys]
    for k in list(crit) + [k for k in ref if k != "source"]:
        if k not in keys:
            keys.append(k)
    rows = []
    for k in keys:
        value = figs.get(k)
        c = crit.get(k)
        if value is None and c is not None and plot_run._is_number(c.get("value")):
            value = float(c["value"])
        cells = _set_cells(by_set, k)
        reference = plot_run._figure_cell(k, ref[k]) if k in ref else ""
        cell = plot_run._figure_cell(k, value)
        if value is None and k == "settling_time_2pct_s" and step.get("verdict") == "not settled":
            cell = "not settled"
        rows.append((k, cell, cells, reference))
    return rows


def overall_verdict(metrics):
    if metrics["passed"] is not None:
        return metrics["passed"]
    flags = [s["passed"] for s in metrics["steps"] if s["passed"] is not None]
    return all(flags) if flags else None


def png_data_uri(path):
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise InputError(f"{path}: not a PNG file")
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def _figure_sort_key(path):
    """step_z.png, step_z_2.png ... in channel order, then overview.png, then the tracking figures."""
    name = os.path.basename(path)
    if name == "overview.png":
        return (2, 0, 0, name)
    if name in plot_run.TRACKING_FIGURE_NAMES:
        return (3, plot_run.TRACKING_FIGURE_NAMES.index(name), 0, name)
    m = re.fullmatch(r"step_([a-z]+)(?:_(\d+))?\.png", name)
    if m and m.group(1) in plot_run.CHANNEL_ORDER:
        return (0, plot_run.CHANNEL_ORDER.index(m.group(1)), int(m.group(2) or 1), name)
    return (1, 0, 0, name)


def figure_files(run_dir, metrics):
    """The figures of this run that are present: the step figures of metrics.json's steps (named as
    plot_run.py names them) and overview.png. Any other PNG in RUN_DIR (left by another run) is not
    this run's and is left out. A tracking run (metrics.json has "tracking") adds its tracking figures."""
    names = plot_run.step_figure_names(metrics["steps"]) + ["overview.png", "outputs.png"]
    if metrics.get("tracking") is not None:
        names += list(plot_run.TRACKING_FIGURE_NAMES)
    files = [os.path.join(run_dir, n) for n in names if os.path.isfile(os.path.join(run_dir, n))]
    return sorted(files, key=_figure_sort_key)


def step_title(step, n):
    # As the step plot's title: the step as commanded, and an angle's shortest path where it differs.
    title = f"{plot_run.step_title(step)} at t = {step['t_step_s']:.2f} s"
    return f"{title} (#{n})" if n > 1 else title


def _short_hash(h):
    return h[:16] + "…" if isinstance(h, str) and len(h) > 16 else (h or "—")


def provenance_rows(metrics):
    """(label, value, full value for the title attribute or None) of the provenance block: what flew
    and how, from metrics.json's "provenance" (docs/outputs.md)."""
    p = metrics.get("provenance")
    if not isinstance(p, dict):
        return []
    c = p.get("controller") if isinstance(p.get("controller"), dict) else {}
    rows = []
    label = plot_run.controller_label(metrics) or "?"
    chosen = ""
    if plot_run.controller_replaced(metrics):
        chosen = f" (in place of the scenario file's {c.get('scenario_type') or '?'})"
    elif c.get("scenario_type"):
        chosen = " (the scenario file's)"
    rows.append(("controller", label + chosen, None))
    py = c.get("python") if isinstance(c.get("python"), dict) else None
    if py:
        rows.append(("Python class", py.get("target") or "?", None))
        rows.append(("module file", py.get("module_file") or "unknown", None))
        rows.append(("module SHA-256", py.get("sha256") or "unknown", None))
    fmu = c.get("fmu") if isinstance(c.get("fmu"), dict) else None
    if fmu:
        rows.append(("FMU", fmu.get("path") or "?", None))
        rows.append(("FMU SHA-256", fmu.get("sha256") or "unknown", None))
    transport = str(p.get("transport", "?"))
    rows.append(("transport", {"inproc": "in-process", "dds": "DDS (plant and controller as two processes)"}
                 .get(transport, transport) + f", {p.get('clock', '?')}", None))
    scen = p.get("scenario") if isinstance(p.get("scenario"), dict) else {}
    rows.append(("scenario file", f"{scen.get('file') or '?'} (SHA-256 {_short_hash(scen.get('sha256'))})",
                 scen.get("sha256")))
    cmd = p.get("command_line")
    if isinstance(cmd, list):
        rows.append(("command line", " ".join(str(a) for a in cmd), None))
    rows.append(("quadcosim", f"{p.get('quadcosim_version', '?')}, git commit {p.get('git_commit', 'unknown')}", None))
    rows.append(("host", str(p.get("host", "?")), None))
    return rows


def provenance_block(w, metrics):
    rows = provenance_rows(metrics)
    if not rows:
        return
    w('<table class="provenance" id="provenance">')
    for label, value, full in rows:
        title = f' title="{esc(full)}"' if full else ""
        w(f"<tr><th>{esc(label)}</th><td{title}>{esc(value)}</td></tr>")
    w("</table>")
    params = ((metrics["provenance"].get("controller") or {}).get("parameters"))
    if isinstance(params, dict) and params:
        w(f"<details><summary>controller parameters ({len(params)})</summary>")
        w('<table class="parameters">')
        for k, v in params.items():
            w(f"<tr><td>{esc(k)}</td><td class=\"num\">{esc(v)}</td></tr>")
        w("</table></details>")


def headline(metrics):
    """The run's headline figure as text: the tracking RMSE of a tracking run, else the first step's
    overshoot and settling time; "" when there is none."""
    tr = metrics.get("tracking")
    if tr:
        figs = tr.get("figures") or {}
        rmse, mx = figs.get("position_rmse_m"), figs.get("position_max_m")
        if plot_run._is_number(rmse):
            after = tr.get("after_s")
            text = f"position tracking RMSE {float(rmse):.4g} m"
            if plot_run._is_number(mx):
                text += f", max {float(mx):.4g} m"
            if plot_run._is_number(after):
                text += f" (from t = {float(after):g} s)"
            return text
        return "position tracking RMSE: not computable (no judged sample)"
    for step in metrics["steps"]:
        f = step["figures"]
        parts = [plot_run.step_title(step)]
        if plot_run._is_number(f.get("overshoot_pct")):
            parts.append(f"overshoot {float(f['overshoot_pct']):.1f} %")
        if plot_run._is_number(f.get("settling_time_2pct_s")):
            parts.append(f"settling {float(f['settling_time_2pct_s']):.2f} s")
        elif step.get("verdict") == "not settled":
            parts.append("not settled")
        return ", ".join(parts)
    return ""


def figure_block(w, paths):
    for path in paths:
        base = os.path.basename(path)
        w(f'<figure><img src="{png_data_uri(path)}" alt="{esc(base)}">'
          f"<figcaption>{esc(base)}</figcaption></figure>")


def step_section(w, metrics):
    w('<h2 id="steps">Step figures</h2>')
    if not metrics["steps"]:
        w("<p>metrics.json lists no steps.</p>")
    counts = {}
    for step in metrics["steps"]:
        ch = step["channel"]
        counts[ch] = counts.get(ch, 0) + 1
        sp = step["passed"]
        mark = "" if sp is None else (" — ok" if sp else " — FAIL")
        w(f"<h3>{esc(step_title(step, counts[ch]))}{esc(mark)}</h3>")
        rows = step_rows(step)
        if not rows:
            w("<p>No step figures.</p>")
            continue
        has_ref = any(r[3] for r in rows)
        w("<table>")
        w(f"<tr><th>figure</th><th>ours</th>{SET_HEADERS}"
          + ("<th>reference</th>" if has_ref else "") + "</tr>")
        for key, ours, cells, reference in rows:
            label = plot_run._figure_label(key, step.get("settling_band_pct", plot_run.DEFAULT_SETTLING_BAND_PCT))
            w(f"<tr><td>{esc(label)}</td><td class=\"num\">{esc(ours)}</td>{cells}"
              + (f"<td class=\"num\">{esc(reference)}</td>" if has_ref else "") + "</tr>")
        w("</table>")
        notes = [c.get("note") for c in step["criteria"] if isinstance(c.get("note"), str) and c.get("note")]
        for note in dict.fromkeys(notes):
            w(f'<p class="note">{esc(note)}</p>')
        if step["reference"].get("source"):
            w(f'<p class="source">reference source: {esc(step["reference"]["source"])}</p>')


def tracking_section(w, tr):
    tp = tr.get("passed")
    mark = "" if not tr.get("criteria") or tp is None else (" — ok" if tp else " — FAIL")
    after = tr.get("after_s")
    after = f"{float(after):g}" if plot_run._is_number(after) else "?"
    w(f'<h2 id="tracking">Trajectory tracking from t = {esc(after)} s{esc(mark)}</h2>')
    figure_table(w, tr, lambda key, v: f"{v:.4g}" + (" m" if key.endswith("_m") else
                                                      (" rad" if key.endswith("_rad") else "")))
    notes = [c.get("note") for c in tr.get("criteria", []) if isinstance(c, dict) and c.get("note")]
    for note in dict.fromkeys(notes):
        w(f'<p class="note">{esc(note)}</p>')


def output_summary(run_dir):
    """The controller's declared figures (trajectory.csv's out.<name> columns) as
    [(name, final, min, max)] over their finite samples (None when it has none); [] without any, or
    without trajectory.csv."""
    path = os.path.join(run_dir, "trajectory.csv")
    if not os.path.isfile(path):
        return []
    try:
        traj = plot_run.load_trajectory(path)
    except plot_run.InputError:
        return []
    rows = []
    for name in traj.output_names():
        v = traj[plot_run.OUTPUT_PREFIX + name]
        finite = v[np.isfinite(v)]
        if finite.size == 0:
            rows.append((name, None, None, None))
        else:
            rows.append((name, float(finite[-1]), float(finite.min()), float(finite.max())))
    return rows


def outputs_section(w, run_dir):
    rows = output_summary(run_dir)
    if not rows:
        return
    w('<h2 id="outputs">The controller\'s own figures</h2>')
    w("<p>What the controller declared and reported at each step (trajectory.csv columns out.&lt;name&gt;; "
      "NaN while it did not report, e.g. under the safety command).</p>")
    w('<table class="outputs"><tr><th>output</th><th>final</th><th>min</th><th>max</th></tr>')
    for name, final, lo, hi in rows:
        cells = "".join(f"<td>{'—' if v is None else esc(f'{v:.6g}')}</td>" for v in (final, lo, hi))
        w(f"<tr><th>{esc(name)}</th>{cells}</tr>")
    w("</table>")


def build_html(run_dir, metrics, version_text):
    verdict = overall_verdict(metrics)
    name = metrics["scenario"] or os.path.basename(os.path.abspath(run_dir))
    out = []
    w = out.append
    w("<!DOCTYPE html>")
    w('<html lang="en">')
    w("<head>")
    w('<meta charset="utf-8">')
    w(f"<title>quadcosim report: {esc(name)}</title>")
    w(f"<style>{CSS}</style>")
    w("</head>")
    w("<body>")
    w(f"<h1>quadcosim run report: {esc(name)}</h1>")
    label = plot_run.controller_label(metrics)
    if label:
        w(f'<p class="flown" id="flown">flown by controller <b>{esc(label)}</b></p>')
    if metrics["description"]:
        if plot_run.controller_replaced(metrics):
            w(f'<p class="description">Scenario file\'s description (written for its own controller, not the '
              f'one that flew): {esc(metrics["description"])}</p>')
        else:
            w(f'<p class="description">{esc(metrics["description"])}</p>')
    judged = metrics.get("judged", "spec")
    judged_text = {"spec": "against the spec (bounds a good controller must meet)",
                   "paper": "against the paper bands (the paper's controller's measured response)"}
    if judged == "none":
        w('<div class="verdict none" id="verdict">FIGURES ONLY (not judged)</div>')
    elif verdict is True:
        w('<div class="verdict passed" id="verdict">PASSED</div>')
    elif verdict is False:
        w('<div class="verdict failed" id="verdict">FAILED</div>')
    else:
        w('<div class="verdict none" id="verdict">NO CRITERIA</div>')
    if judged != "none":
        w(f'<p class="source" id="judged">judged {esc(judged_text.get(judged, judged))}</p>')
    w('<p class="source">spec: the scenario\'s specification, bounds a good controller must meet. paper: the '
      "paper's controller's response, bands around its measured figures (not a specification). The judged "
      "set's checks read ok/FAIL, the other's in/out.</p>")
    head = headline(metrics)
    if head:
        w(f'<p class="headline" id="headline">{esc(head)}</p>')
    provenance_block(w, metrics)

    # The headline figure first: a tracking run's tracking, a step run's steps; each with its plots.
    files = figure_files(run_dir, metrics)
    step_names = set(plot_run.step_figure_names(metrics["steps"]))
    step_files = [f for f in files if os.path.basename(f) in step_names]
    tracking_files = [f for f in files if os.path.basename(f) in plot_run.TRACKING_FIGURE_NAMES]
    output_files = [f for f in files if os.path.basename(f) == "outputs.png"]
    other_files = [f for f in files if f not in step_files and f not in tracking_files and f not in output_files]
    tr = metrics.get("tracking")
    if tr:
        tracking_section(w, tr)
        figure_block(w, tracking_files)
        if metrics["steps"]:
            step_section(w, metrics)
            figure_block(w, step_files)
    else:
        step_section(w, metrics)
        figure_block(w, step_files)

    hold = metrics.get("hold")
    if hold:
        hp = hold.get("passed")
        w(f"<h2>Position hold from t = {esc(str(hold.get('after_s')))} s"
          f"{esc('' if hp is None else (' — ok' if hp else ' — FAIL'))}</h2>")
        figure_table(w, hold, lambda key, v: f"{v:.3f} m")

    sat = metrics.get("saturation")
    if sat:
        sp = sat.get("passed")
        mark = "" if not sat.get("criteria") or sp is None else (" — ok" if sp else " — FAIL")
        w(f'<h2 id="saturation">Saturation and control effort{esc(mark)}</h2>')
        figure_table(w, sat, lambda key, v: f"{v:.3f} {'N' if key.endswith('_n') else 's'}")

    outputs_section(w, run_dir)
    figure_block(w, output_files)

    w("<h2>Figures</h2>" if not (step_files or tracking_files) else "<h2>Overview</h2>")
    if not files:
        w("<p>No figures in the run directory (run tools/plot_run.py first).</p>")
    figure_block(w, other_files)

    w("<h2>Scenario as flown (scenario.yaml)</h2>")
    scen = os.path.join(run_dir, "scenario.yaml")
    if os.path.isfile(scen):
        try:
            with open(scen, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError as exc:
            raise InputError(f"{scen}: cannot read: {exc}") from None
        w(f"<pre>{esc(text)}</pre>")
    else:
        w("<p>scenario.yaml not found in the run directory.</p>")

    w("<h2>Versions</h2>")
    w('<table class="versions">')
    qv = version_text.strip() if version_text and version_text.strip() else "unknown"
    for label, value in (("quadcosim", qv), ("Python", platform.python_version()),
                         ("numpy", np.__version__), ("matplotlib", matplotlib.__version__)):
        w(f"<tr><th>{esc(label)}</th><td>{esc(value)}</td></tr>")
    w("</table>")
    w("</body>")
    w("</html>")
    return "\n".join(out) + "\n"


def run(run_dir, version_text=None):
    if not os.path.isdir(run_dir):
        raise InputError(f"{run_dir}: run directory not found")
    metrics_path = os.path.join(run_dir, "metrics.json")
    metrics = plot_run.load_metrics(metrics_path)
    if metrics is None:
        raise InputError(f"{metrics_path}: file not found (metrics.json is required)")
    page = build_html(run_dir, metrics, version_text)
    out = os.path.join(run_dir, "report.html")
    tmp = out + ".tmp"
    with open(tmp, "w", encoding="utf-8", newline="\n") as f:
        f.write(page)
    os.replace(tmp, out)
    print(out, flush=True)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog=PROG, description="Write RUN_DIR/report.html, a self-contained HTML run report.")
    parser.add_argument("run_dir", metavar="RUN_DIR", help="run directory holding metrics.json")
    parser.add_argument("--version-text", default=None, metavar="TEXT",
                        help="quadcosim version text (e.g. the output of `quadcosim --version`)")
    args = parser.parse_args(argv)
    try:
        run(args.run_dir, args.version_text)
    except (InputError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
