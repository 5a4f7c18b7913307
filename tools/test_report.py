#!/usr/bin/python3
"""Tests for tools/report.py and tools/compare_runs.py.

Run:  /usr/bin/python3 tools/test_report.py   (stdlib unittest; the synthetic
run directories come from test_plot_run.make_run()). The headless-Chromium
rendering test is skipped when /usr/bin/chromium is absent.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from test_plot_run import make_run, make_tracking_run, plot_python, png_size  # noqa: E402

REPORT = os.path.join(HERE, "report.py")
COMPARE = os.path.join(HERE, "compare_runs.py")
PLOT = os.path.join(HERE, "plot_run.py")
CHROMIUM = "/usr/bin/chromium"

SCENARIO_YAML = """\
# synthetic scenario for the report test: <b>not bold</b> & escaped
name: synthetic
description: "altitude step 0 -> 10 m"
schedule:
  - at_s: 0
    set: {z_des: 10.0}
"""


class ToolTestBase(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="report_test_")
        self.tmp = self._tmp.name
        self.env = dict(os.environ, MPLCONFIGDIR=os.path.join(self.tmp, "mplconfig"))

    def tearDown(self):
        self._tmp.cleanup()

    def run_tool(self, *args, timeout=180):
        return subprocess.run([plot_python(), *args], capture_output=True, text=True,
                              timeout=timeout, env=self.env)

    def make_plotted_run(self, name, steps, **kw):
        run = os.path.join(self.tmp, name)
        make_run(run, steps, n_rows=1001, **kw)
        res = self.run_tool(PLOT, run)
        self.assertEqual(res.returncode, 0, res.stderr)
        return run


class ReportTest(ToolTestBase):
    def make_report(self):
        run = self.make_plotted_run("run", [("z", 0.0, 0.0, 10.0)])
        with open(os.path.join(run, "scenario.yaml"), "w") as f:
            f.write(SCENARIO_YAML)
        res = self.run_tool(REPORT, run, "--version-text", "quadcosim 9.8.7\n")
        self.assertEqual(res.returncode, 0, res.stderr)
        path = os.path.join(run, "report.html")
        self.assertIn(path, res.stdout.splitlines())
        with open(path, encoding="utf-8") as f:
            page = f.read()
        with open(os.path.join(run, "metrics.json")) as f:
            metrics = json.load(f)
        return run, path, page, metrics

    def report_with_metrics(self, edit):
        """report.html of an unplotted roll-step run whose metrics.json `edit(m)` changed in place."""
        run = os.path.join(self.tmp, "run")
        make_run(run, [("roll", 1.0, 0.0, 0.1)], n_rows=300)
        with open(os.path.join(run, "metrics.json")) as f:
            m = json.load(f)
        edit(m)
        with open(os.path.join(run, "metrics.json"), "w") as f:
            json.dump(m, f)
        res = self.run_tool(REPORT, run)
        self.assertEqual(res.returncode, 0, res.stderr)
        with open(os.path.join(run, "report.html"), encoding="utf-8") as f:
            return f.read()

    def test_provenance_block_of_a_python_controller(self):
        sha = "ab" * 32
        prov = {"controller": {"label": "python pd:AltitudePD", "type": "python", "scenario_type": "python",
                               "override": None, "parameters": {"kp_z": 4.0},
                               "python": {"target": "pd:AltitudePD", "module_file": "/x/pd.py", "sha256": sha}},
                "transport": "dds", "clock": "realtime", "command_line": ["quadcosim", "run", "s.yaml"],
                "quadcosim_version": "1.2.3", "git_commit": "unknown", "host": "h<1>",
                "scenario": {"file": "s.yaml", "name": "s", "sha256": None, "effective": "scenario.yaml"}}
        page = self.report_with_metrics(lambda m: m.update(provenance=prov, description="my <PD>"))
        self.assertIn('flown by controller <b>python pd:AltitudePD</b>', page)
        self.assertIn("<td>python pd:AltitudePD (the scenario file&#x27;s)</td>", page)
        self.assertIn(f"<td>{sha}</td>", page)  # the module's hash in full
        self.assertIn("<td>/x/pd.py</td>", page)
        self.assertIn("<td>DDS (plant and controller as two processes), realtime</td>", page)
        self.assertIn("<td>1.2.3, git commit unknown</td>", page)
        self.assertIn("<td>h&lt;1&gt;</td>", page)
        self.assertIn('<p class="description">my &lt;PD&gt;</p>', page)  # its own controller flew
        self.assertLess(page.index('id="verdict"'), page.index('id="provenance"'))
        self.assertLess(page.index('id="provenance"'), page.index('id="steps"'))

    def test_report_contents(self):
        run, path, page, metrics = self.make_report()
        step = metrics["steps"][0]
        self.assertIn("synthetic", page)
        self.assertIn("synthetic second-order responses", page)
        self.assertIn("PASSED", page)
        # our values, the criterion band, the reference value and its source
        self.assertIn(f"{step['figures']['overshoot_pct']:.1f} %", page)
        self.assertIn(f"{step['figures']['settling_time_2pct_s']:.2f} s", page)
        self.assertIn("[15, 21]", page)
        self.assertIn("≤ 10", page)
        self.assertIn(">ok<", page)
        self.assertIn("18.0 %", page)  # reference overshoot
        self.assertIn("paper Fig. 4", page)
        # figures embedded: step_z.png and overview.png
        self.assertEqual(page.count("data:image/png;base64,"), 2)
        # nothing external
        self.assertIsNone(re.search(r"""(src|href)\s*=\s*["']?\s*https?://""", page, re.I))
        self.assertNotIn("http://", page)
        self.assertNotIn("https://", page)
        # scenario YAML escaped, versions present
        self.assertIn("&lt;b&gt;not bold&lt;/b&gt; &amp; escaped", page)
        self.assertNotIn("<b>not bold</b>", page)
        self.assertIn("quadcosim 9.8.7", page)
        self.assertIn("matplotlib", page)

    def test_report_is_reproducible(self):
        run, path, page, _ = self.make_report()
        res = self.run_tool(REPORT, run, "--version-text", "quadcosim 9.8.7\n")
        self.assertEqual(res.returncode, 0, res.stderr)
        with open(path, encoding="utf-8") as f:
            self.assertEqual(f.read(), page)

    def test_only_this_runs_figures(self):
        # A PNG another run left in the folder (step_x.png of a roll scenario) is not this run's.
        run = self.make_plotted_run("run", [("z", 0.0, 0.0, 10.0)])
        shutil.copy(os.path.join(run, "step_z.png"), os.path.join(run, "step_x.png"))
        res = self.run_tool(REPORT, run)
        self.assertEqual(res.returncode, 0, res.stderr)
        with open(os.path.join(run, "report.html"), encoding="utf-8") as f:
            page = f.read()
        self.assertEqual(page.count("data:image/png;base64,"), 2)
        self.assertIn(">step_z.png<", page)
        self.assertNotIn("step_x.png", page)

    def test_tracking_table_and_figures(self):
        run = os.path.join(self.tmp, "run")
        make_tracking_run(run)
        res = self.run_tool(PLOT, run)
        self.assertEqual(res.returncode, 0, res.stderr)
        res = self.run_tool(REPORT, run)
        self.assertEqual(res.returncode, 0, res.stderr)
        with open(os.path.join(run, "report.html"), encoding="utf-8") as f:
            page = f.read()
        self.assertIn("Trajectory tracking from t = 5 s — ok", page)
        self.assertIn(">position_rmse_m<", page)
        self.assertIn(">0.03 m<", page)
        self.assertIn("≤ 0.05", page)
        # the headline first: the tracking table and its three figures, then overview
        self.assertEqual(page.count("data:image/png;base64,"), 4)
        order = [page.index(f">{n}<") for n in ("tracking_path.png", "tracking_axes.png", "tracking_error.png",
                                               "overview.png")]
        self.assertEqual(order, sorted(order))
        self.assertLess(page.index('id="tracking"'), page.index('id="steps"') if 'id="steps"' in page else len(page))
        self.assertIn('id="headline">position tracking RMSE 0.03 m', page)

    def test_failed_tracking_criterion_shows_fail(self):
        def fail_tracking(m):
            m["tracking"] = {"after_s": 10, "reference_period_s": 0.02, "samples": 0,
                             "figures": {"position_rmse_m": 0.2},
                             "criteria": [{"figure": "position_rmse_m", "min": None, "max": 0.05, "value": 0.2,
                                           "passed": False, "note": None}],
                             "passed": False}
            m["passed"] = False
        page = self.report_with_metrics(fail_tracking)
        self.assertIn("Trajectory tracking from t = 10 s — FAIL", page)
        self.assertIn(">0.2 m<", page)
        self.assertIn(">FAILED<", page)

    def test_failed_verdict(self):
        def fail_roll(m):
            m["steps"][0]["criteria"][0]["passed"] = False
            m["steps"][0]["passed"] = False
            m["passed"] = False
        page = self.report_with_metrics(fail_roll)
        self.assertIn(">FAILED<", page)
        self.assertIn(">FAIL<", page)
        self.assertNotIn("data:image/png;base64,", page)  # no plots were made

    def test_settling_label_names_the_steps_band(self):
        # settling_band_pct from metrics.json (5 in the noisy-IMU roll scenario); 2 when absent.
        def band5(m):
            m["steps"][0]["settling_band_pct"] = 5
        page = self.report_with_metrics(band5)
        self.assertIn("<td>settle 5%</td>", page)
        self.assertNotIn("settle 2%", page)
        page = self.report_with_metrics(lambda m: None)
        self.assertIn("<td>settle 2%</td>", page)

    def test_hold_section(self):
        # A position-hold block (analysis.hold) is shown with its values, bands and verdict.
        def add_hold(m):
            m["hold"] = {"after_s": 10.0,
                         "figures": {"max_horizontal_error_m": 0.6125, "rms_horizontal_error_m": 0.25,
                                     "max_vertical_error_m": None},
                         "criteria": [{"figure": "max_horizontal_error_m", "min": None, "max": 0.5,
                                       "value": 0.6125, "passed": False}],
                         "passed": False}
            m["passed"] = False
        page = self.report_with_metrics(add_hold)
        self.assertIn("Position hold from t = 10.0 s — FAIL", page)
        self.assertIn("0.613 m", page)
        self.assertIn("≤ 0.5", page)
        self.assertIn(">FAILED<", page)

    def test_missing_or_malformed_metrics_is_an_error(self):
        run = os.path.join(self.tmp, "run")
        make_run(run, [("z", 0.0, 0.0, 10.0)], n_rows=200, with_metrics=False)
        res = self.run_tool(REPORT, run)
        self.assertEqual(res.returncode, 1)
        self.assertIn("metrics.json", res.stderr)
        with open(os.path.join(run, "metrics.json"), "w") as f:
            f.write('{"steps": [')
        res = self.run_tool(REPORT, run)
        self.assertEqual(res.returncode, 1)
        self.assertIn("metrics.json", res.stderr)
        self.assertFalse(os.path.exists(os.path.join(run, "report.html")))

    @unittest.skipUnless(os.path.exists(CHROMIUM), f"{CHROMIUM} not installed")
    def test_renders_in_headless_chromium(self):
        run, path, page, _ = self.make_report()
        shot = os.path.join(self.tmp, "shot.png")
        url = "file://" + os.path.abspath(path)

        def chromium(*extra, profile):
            return subprocess.run(
                [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={os.path.join(self.tmp, profile)}", *extra, url],
                capture_output=True, text=True, timeout=120)

        res = chromium(f"--screenshot={shot}", "--window-size=1200,2000", profile="profile1")
        self.assertTrue(os.path.isfile(shot), f"no screenshot; chromium stderr:\n{res.stderr}")
        w, h = png_size(shot)
        self.assertEqual((w, h), (1200, 2000))
        self.assertGreater(os.path.getsize(shot), 20_000, "screenshot suspiciously small")

        res = chromium("--dump-dom", profile="profile2")
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assertIn("PASSED", res.stdout)
        self.assertIn('id="verdict"', res.stdout)


class CompareTest(ToolTestBase):
    def test_compare_two_runs(self):
        run_a = self.make_plotted_run("run_a", [("z", 0.0, 0.0, 10.0)])
        run_b = self.make_plotted_run("run_b", [("z", 0.0, 0.0, 10.0)])
        # B: a different overshoot (as if retuned)
        mpath = os.path.join(run_b, "metrics.json")
        with open(mpath) as f:
            m = json.load(f)
        m["steps"][0]["figures"]["overshoot_pct"] = 12.34
        with open(mpath, "w") as f:
            json.dump(m, f)
        with open(os.path.join(run_a, "metrics.json")) as f:
            over_a = json.load(f)["steps"][0]["figures"]["overshoot_pct"]

        res = self.run_tool(COMPARE, run_a, run_b)
        self.assertEqual(res.returncode, 0, res.stderr)
        out_dir = os.path.join(run_b, "compare_with_run_a")
        png = os.path.join(out_dir, "compare_z.png")
        self.assertTrue(os.path.isfile(png))
        self.assertGreater(os.path.getsize(png), 10_000)
        png_size(png)
        self.assertFalse(os.path.exists(os.path.join(out_dir, "compare_roll.png")))
        row = [ln for ln in res.stdout.splitlines() if ln.startswith("| overshoot |")]
        self.assertEqual(len(row), 1, res.stdout)
        self.assertIn(f"{over_a:.1f} %", row[0])
        self.assertIn("12.3 %", row[0])
        self.assertIn(f"{12.34 - over_a:+.1f} %", row[0])
        with open(os.path.join(out_dir, "compare.md"), encoding="utf-8") as f:
            self.assertEqual(f.read(), res.stdout)

    def test_compare_names_both_settling_bands(self):
        run_a = os.path.join(self.tmp, "a")
        run_b = os.path.join(self.tmp, "b")
        make_run(run_a, [("roll", 1.0, 0.0, 0.1)], n_rows=300)
        make_run(run_b, [("roll", 1.0, 0.0, 0.1)], n_rows=300)
        mpath = os.path.join(run_b, "metrics.json")
        with open(mpath) as f:
            m = json.load(f)
        m["steps"][0]["settling_band_pct"] = 5
        with open(mpath, "w") as f:
            json.dump(m, f)
        res = self.run_tool(COMPARE, run_a, run_b, "--out", os.path.join(self.tmp, "cmp"))
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assertIn("| settle 2%/5% |", res.stdout)

    def test_compare_out_dir_and_channel_in_one_run(self):
        run_a = self.make_plotted_run("a", [("z", 0.0, 0.0, 10.0)])
        run_b = self.make_plotted_run("b", [("z", 0.0, 0.0, 10.0), ("yaw", 5.0, 0.0, 0.2)])
        out = os.path.join(self.tmp, "cmp")
        res = self.run_tool(COMPARE, run_a, run_b, "--out", out)
        self.assertEqual(res.returncode, 0, res.stderr)
        for ch in ("z", "yaw"):
            self.assertTrue(os.path.isfile(os.path.join(out, f"compare_{ch}.png")), ch)
        self.assertIn("Yaw step", res.stdout)
        self.assertIn("only in run B", res.stdout)

    def test_compare_missing_run_is_an_error(self):
        run_a = os.path.join(self.tmp, "a")
        make_run(run_a, [("z", 0.0, 0.0, 10.0)], n_rows=200)
        res = self.run_tool(COMPARE, run_a, os.path.join(self.tmp, "nope"))
        self.assertEqual(res.returncode, 1)
        self.assertIn("nope", res.stderr)


if __name__ == "__main__":
    unittest.main()
