#!/usr/bin/python3
"""index.html of a quadcosim sweep directory: one page to see its results.

Usage: sweep_index.py SWEEP_DIR

Reads SWEEP_DIR/summary.json and each run's runs/NNNN/metrics.json and writes
SWEEP_DIR/index.html, a page that opens offline (inline CSS and a few lines of
inline script to sort the table; no URL outside the folder) with

  - the verdict: runs passed of runs, the seed, the varied keys and their specs
    (and "interrupted" for a partial summary);
  - the headline scatter plots of tools/plot_sweep.py (headline_<key>.png: the
    figures the scenario's criteria bound against each varied key, passing runs
    green, failing red) and links to every other plot it wrote;
  - a table of every run: its index, PASS or FAIL and, for a failed run, each
    criterion it failed with its value and the bound it is outside (or the note
    saying why it could not be judged), or the error of a run that could not be
    flown; each varied key's value, the headline figures, links to the run's
    folder, its metrics.json, and its report.html and trajectory.csv when
    present (`quadcosim sweep rerun` makes a run's report), and its seed.

A run's verdict and failed criteria are read from its own metrics.json (its
"passed" and each section's criteria with "passed": false), so whatever the
criteria layer writes there is what the page shows; summary.json gives them for
a run without metrics.json (a merged folder, whose runs are in the shards', or
a run that could not be flown). No date is written: the same folder gives the
same bytes. Exit status: 0 on success, 1 when summary.json is missing or
malformed (the message names the file), 2 on a usage error.
"""

import html
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import sweep_results  # noqa: E402  (what plot_sweep.py reads too: headline figures, file names)
from sweep_results import InputError  # noqa: E402

CSS = """
body { font-family: "DejaVu Sans", Arial, Helvetica, sans-serif; margin: 24px; color: #222; line-height: 1.4; }
h1 { margin-bottom: 0.2em; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
.verdict { font-size: 1.3em; font-weight: bold; padding: 0.4em 0.8em; border-radius: 6px; color: #fff;
           display: inline-block; }
.verdict.passed { background: #2a7f2a; }
.verdict.failed { background: #c62828; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #eee; cursor: pointer; position: sticky; top: 0; }
td.num { text-align: right; font-family: "DejaVu Sans Mono", monospace; }
td.pass { color: #2a7f2a; font-weight: bold; }
td.fail { color: #c62828; font-weight: bold; }
td.why { min-width: 22em; max-width: 40em; }
td.seed { color: #777; font-size: 0.85em; }
tr.failed { background: #fdf0f0; }
.plots img { max-width: 100%; border: 1px solid #ddd; margin: 0.3em 0; }
.small { color: #555; font-size: 0.9em; }
code { background: #f4f4f4; padding: 0 3px; }
"""

# Click a column's heading to sort by it (numbers as numbers), again to reverse.
SCRIPT = """
document.querySelectorAll("table.runs th").forEach(function (th, col) {
  th.addEventListener("click", function () {
    var body = th.closest("table").tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var down = th.dataset.down !== "1";
    th.dataset.down = down ? "1" : "0";
    rows.sort(function (a, b) {
      var x = a.cells[col].dataset.v !== undefined ? a.cells[col].dataset.v : a.cells[col].textContent;
      var y = b.cells[col].dataset.v !== undefined ? b.cells[col].dataset.v : b.cells[col].textContent;
      var nx = parseFloat(x), ny = parseFloat(y);
      var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : (x < y ? -1 : x > y ? 1 : 0);
      return down ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  });
});
document.getElementById("only-failed").addEventListener("change", function (e) {
  document.querySelectorAll("table.runs tbody tr").forEach(function (r) {
    r.style.display = e.target.checked && !r.classList.contains("failed") ? "none" : "";
  });
});
"""


def esc(s):
    return html.escape(str(s), quote=True)


def num(v):
    if v is None:
        return "&ndash;"
    if isinstance(v, bool):
        return esc(v)
    if isinstance(v, (int, float)):
        return esc(f"{v:.4g}")
    return esc(v)


def run_dir_of(index):
    return os.path.join("runs", f"{index:04d}")


def read_metrics(sweep_dir, index):
    path = os.path.join(sweep_dir, run_dir_of(index), "metrics.json")
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        return None
    except (OSError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not a run's metrics ({e})")


def failed_criteria(metrics):
    """Each criterion metrics.json marks failed: (channel, figure, value, bound, side, note)."""
    out = []
    for ch, section in sweep_results.criteria_sections(metrics):
        for c in section.get("criteria", []):
            if c.get("passed") is not False or c.get("judged") is False:  # not judged: the other set's band
                continue
            v, lo, hi = c.get("value"), c.get("min"), c.get("max")
            bound, side = None, None
            if isinstance(v, (int, float)):
                if lo is not None and v < lo:
                    bound, side = lo, "min"
                elif hi is not None and v > hi:
                    bound, side = hi, "max"
            out.append({"channel": ch, "name": c.get("figure"), "value": v, "bound": bound, "side": side,
                        "min": lo, "max": hi, "note": c.get("note")})
    return out


def describe(fc):
    """One failed criterion as text: "z.overshoot_pct = 0 < min 15" or why it has no value."""
    name = f"{fc.get('channel')}.{fc.get('name')}"
    v = fc.get("value")
    if fc.get("side") == "min":
        return f"{name} = {v:.4g} < min {fc['bound']:.4g}"
    if fc.get("side") == "max":
        return f"{name} = {v:.4g} > max {fc['bound']:.4g}"
    lo = "-inf" if fc.get("min") is None else f"{fc['min']:.4g}"
    hi = "inf" if fc.get("max") is None else f"{fc['max']:.4g}"
    band = f"[{lo}, {hi}]"
    value = "no value" if v is None else f"{v:.4g}"
    note = fc.get("note")
    return f"{name} = {value}, band {band}" + (f": {note}" if note else "")


def varied_specs(summary):
    return [(v.get("spec", ""), [k["path"] for k in v.get("keys", [])]) for v in summary.get("vary", [])]


JUDGED_TEXT = {"spec": "judged against the scenario's spec (bounds a good controller must meet)",
               "paper": "judged against the paper bands (the paper's controller's measured response)",
               "none": "figures only (not judged)"}


def flown_text(metrics, summary):
    """"flown by controller LABEL (transport inproc, quadcosim VERSION); judged against ...": what every
    run of the sweep flew, from a run's metrics.json provenance, and the set judged."""
    judged = JUDGED_TEXT.get(summary.get("judge", "spec"), summary.get("judge", "spec"))
    p = (metrics or {}).get("provenance") or {}
    label = (p.get("controller") or {}).get("label")
    if not label:
        return judged[0].upper() + judged[1:]
    how = ", ".join(x for x in (f"transport {p['transport']}" if p.get("transport") else "",
                                f"quadcosim {p['quadcosim_version']}" if p.get("quadcosim_version") else "") if x)
    return f"flown by controller {label}{f' ({how})' if how else ''}; {judged}"


def build(sweep_dir, summary):
    runs = summary["per_run"]
    keys = sweep_results.varied_keys(summary)
    headline = sweep_results.headline_figures(sweep_dir, summary)
    n_runs, n_done = summary["runs"], len(runs)
    rows = []
    flown = None  # the first run's metrics.json: what flew (its provenance) and the set judged
    for r in runs:
        i = r["index"]
        m = read_metrics(sweep_dir, i)
        if m is not None:  # the run's own verdict and criteria (named for a failed run, as summary.json does)
            passed = bool(m.get("passed"))
            failed = [] if passed else failed_criteria(m)
        else:
            passed, failed = bool(r.get("passed")), r.get("failed_criteria", [])
        rows.append((r, m is not None, passed, failed))
        if m is not None and flown is None:
            flown = m
    passed_runs = sum(1 for row in rows if row[2])

    out = []
    w = out.append
    w("<!DOCTYPE html>")
    w('<html lang="en"><head><meta charset="utf-8">')
    w(f"<title>sweep {esc(summary.get('scenario', ''))}</title>")
    w(f"<style>{CSS}</style></head><body>")
    w(f"<h1>Sweep {esc(summary.get('scenario', ''))}</h1>")
    cls = "passed" if passed_runs == n_done else "failed"
    partial = summary.get("partial")
    text = (f"{passed_runs} of {n_done} runs passed" if not partial
            else f"interrupted: {n_done} of {n_runs} runs finished, {passed_runs} of them passed")
    w(f'<div class="verdict {cls}">{esc(text)}'
      f"{'' if n_done == 0 else f' ({100.0 * passed_runs / n_done:.1f} %)'}</div>")
    w(f'<p class="flown" id="flown">{esc(flown_text(flown, summary))}</p>')
    w(f'<p class="small">seed {esc(summary.get("seed"))}, sampler {esc(summary.get("sampler", "random"))}, '
      f'{esc(summary.get("runs_per_point", 1))} runs per point; scenario '
      f'<a href="scenario.yaml">scenario.yaml</a> (a copy of <code>{esc(summary.get("scenario_file", ""))}</code>); '
      f'<a href="summary.json">summary.json</a></p>')
    if varied_specs(summary):
        w("<p>Varied: " + ", ".join(f"<code>--vary {esc(spec)}</code>" for spec, _ in varied_specs(summary)) + "</p>")

    w("<h2>Plots</h2>")
    if headline:
        w(f'<p class="small">Headline figures (the criteria\'s): {", ".join(f"<code>{esc(h)}</code>" for h in headline)}; '
          "passing runs green, failing red, bounds dotted.</p>")
    w('<div class="plots">')
    shown = 0
    names = ", ".join(headline)
    for key in keys:
        png = f"headline_{sweep_results.safe(key)}.png"
        if os.path.isfile(os.path.join(sweep_dir, png)):
            w(f'<p><a href="{esc(png)}"><img src="{esc(png)}" alt="{esc(names)} against {esc(key)}"></a></p>')
            shown += 1
    for png in ("map_pass.png",):
        if os.path.isfile(os.path.join(sweep_dir, png)):
            w(f'<p><a href="{esc(png)}"><img src="{esc(png)}" alt="runs passed per grid point"></a></p>')
            shown += 1
    w("</div>")
    others = sorted(f for f in os.listdir(sweep_dir)
                    if f.endswith(".png") and not f.startswith("headline_") and f != "map_pass.png")
    if others:
        w("<p>All plots: " + ", ".join(f'<a href="{esc(f)}">{esc(f)}</a>' for f in others) + "</p>")
    elif not shown:
        w('<p class="small">No plots (the sweep ran with --no-plots, or no run has a figure).</p>')

    w(f"<h2>Runs ({n_done})</h2>")
    w('<p class="small"><label><input type="checkbox" id="only-failed"> only the failed runs</label>; '
      "click a column to sort. A run's full outputs (trajectory, report.html): "
      f"<code>quadcosim sweep rerun {esc(sweep_dir)} INDEX --out DIR</code>.</p>")
    # What failed first, then the run's values and figures; the seed last (20 digits).
    w('<table class="runs"><thead><tr><th>run</th><th>verdict</th><th>failed criteria</th>')
    for key in keys:
        w(f"<th>{esc(key)}</th>")
    for h in headline:
        w(f"<th>{esc(h)}</th>")
    w("<th>outputs</th><th>seed</th></tr></thead><tbody>")
    for r, has_metrics, passed, failed in rows:
        i = r["index"]
        w(f'<tr id="run{i}"' + ("" if passed else ' class="failed"') + ">")
        w(f'<td class="num" data-v="{i}">{i}</td>')
        w(f'<td class="{"pass" if passed else "fail"}">{"PASS" if passed else "FAIL"}</td>')
        if r.get("error"):
            w(f'<td class="why">could not be flown: {esc(r["error"])}</td>')
        else:
            w('<td class="why">' + "<br>".join(esc(describe(fc)) for fc in failed) + "</td>")
        for key in keys:
            v = r.get("values", {}).get(key)
            w(f'<td class="num" data-v="{esc(v if v is not None else "")}">{num(v)}</td>')
        for h in headline:
            v = r.get("figures", {}).get(h)
            w(f'<td class="num" data-v="{esc(v if v is not None else "")}">{num(v)}</td>')
        links = []
        d = run_dir_of(i)
        if os.path.isdir(os.path.join(sweep_dir, d)):
            links.append(f'<a href="{esc(d)}/">folder</a>')
        if has_metrics:
            links.append(f'<a href="{esc(d)}/metrics.json">metrics.json</a>')
        for extra in ("report.html", "trajectory.csv"):
            if os.path.isfile(os.path.join(sweep_dir, d, extra)):
                links.append(f'<a href="{esc(d)}/{extra}">{extra}</a>')
        w("<td>" + " ".join(links) + f'</td><td class="num seed">{esc(r.get("seed", ""))}</td></tr>')
    w("</tbody></table>")
    w(f"<script>{SCRIPT}</script>")
    w("</body></html>")
    return "\n".join(out) + "\n"


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    sweep_dir = argv[1]
    try:
        summary = sweep_results.load(sweep_dir)
        page = build(sweep_dir, summary)
    except InputError as e:
        print(f"sweep_index.py: error: {e}", file=sys.stderr)
        return 1
    path = os.path.join(sweep_dir, "index.html")
    tmp = path + ".tmp"
    if os.path.lexists(tmp):
        os.unlink(tmp)  # a leftover of an interrupted write (or a link): never written through
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, path)  # the old page or the new one, never a part; a link at path is replaced
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
