#!/usr/bin/python3
"""Measure how quadcosim's cost grows with the number of vehicles and with the RK4 sub-steps, and plot it.

Usage: perf_scaling.py BINARY OUT_PNG [--json OUT_JSON] [--quick]

Runs (each a real quadcosim command, wall clock on this machine):
  - in-process swarms of N vehicles (scenarios/swarm/grid_takeoff.yaml, 2 threads, short runs):
    real-time factor and wall time per vehicle-tick;
  - DDS swarms of N vehicles (one plant and one controller process, 2 threads each);
  - one vehicle in-process with 1, 2, 4, 8 RK4 sub-steps per tick (quadcosim bench --only inproc).
Writes OUT_PNG (three panels) and prints Markdown tables; --json also saves the numbers.
DDS runs use ROS_DOMAIN_ID from the environment (set one nobody else uses).
Only the standard library and matplotlib (Debian's python3-matplotlib).
"""
import json
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIOS = os.path.join(os.path.dirname(HERE), "scenarios")


def scenario_copy(tmp, src, name, duration_s=None, substeps=None):
    text = open(src).read()
    if duration_s is not None:
        text = re.sub(r"duration_s: [0-9.]+", f"duration_s: {duration_s}", text, count=1)
    text = re.sub(r"\n  record_vehicles: \[[^\]]*\]", "", text)  # recording off: speed only
    if substeps is not None:
        text = text.replace("simulation:\n", f"simulation:\n  substeps: {substeps}\n", 1)
    path = os.path.join(tmp, name)
    open(path, "w").write(text)
    return path


def swarm_rtf(binary, tmp, scenario, n, transport):
    out = os.path.join(tmp, f"run_{transport}_{n}")
    cmd = [binary, "run", scenario, "--vehicles", str(n), "--out", out, "--no-plots", "--transport", transport]
    subprocess.run(cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=900)
    try:
        return json.load(open(os.path.join(out, "summary.json")))
    except (OSError, ValueError):
        return None


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    binary, png = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    out_json = sys.argv[sys.argv.index("--json") + 1] if "--json" in sys.argv else None
    tmp = tempfile.mkdtemp(prefix="quadcosim-scaling-")
    grid = os.path.join(SCENARIOS, "swarm", "grid_takeoff.yaml")
    paper = os.path.join(SCENARIOS, "paper", "altitude_step.yaml")
    results = {"inproc": [], "dds": [], "substeps": []}

    inproc_n = [1, 10, 100, 1000, 10000, 50000, 100000] if not quick else [1, 10, 100]
    for n in inproc_n:
        s = scenario_copy(tmp, grid, f"grid_{n}.yaml", duration_s=2 if n > 1000 else 10)
        r = swarm_rtf(binary, tmp, s, n, "inproc")
        if r:
            ticks = r["simulated_s"] * 100 + 1
            results["inproc"].append({"vehicles": n, "rtf": r["real_time_factor"],
                                      "ns_per_vehicle_tick": r["wall_s"] / (n * ticks) * 1e9})
            print(f"inproc {n}: {r['real_time_factor']:.1f}x", file=sys.stderr)

    dds_n = [1, 8, 32, 128, 256, 512] if not quick else [1, 4]
    for n in dds_n:
        # At least ~0.5 s of wall time per trial, so start-up and single stalls do not dominate.
        s = scenario_copy(tmp, grid, f"grid_dds_{n}.yaml", duration_s=120 if n == 1 else 40 if n <= 32 else 4)
        r = swarm_rtf(binary, tmp, s, n, "dds")
        if r:
            results["dds"].append({"vehicles": n, "rtf": r["real_time_factor"]})
            print(f"dds {n}: {r['real_time_factor']:.2f}x", file=sys.stderr)

    for sub in [1, 2, 4, 8]:
        s = scenario_copy(tmp, paper, f"paper_sub{sub}.yaml", substeps=sub)
        p = subprocess.run([binary, "bench", "--only", "inproc", "--seconds", "100" if quick else "600",
                            "--scenario", s, "--json"], capture_output=True, text=True, timeout=600)
        j = json.loads(p.stdout)
        results["substeps"].append({"substeps": sub, "rtf": j["inproc_rtf"],
                                    "ns_per_tick": 1e7 / j["inproc_rtf"]})
        print(f"substeps {sub}: {j['inproc_rtf']:.0f}x", file=sys.stderr)

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    for key, label, style in (("inproc", "in-process (2 threads)", "o-"), ("dds", "DDS lockstep (2+2 threads)", "s-")):
        xs = [r["vehicles"] for r in results[key]]
        ax[0].loglog(xs, [r["rtf"] for r in results[key]], style, label=label)
    ax[0].axhline(1.0, color="grey", ls="--", lw=1)
    ax[0].set_xlabel("vehicles N")
    ax[0].set_ylabel("real-time factor")
    ax[0].set_title("Swarm speed vs N (>= 1 above the dashed line)")
    ax[0].legend()
    ax[0].grid(True, which="both", alpha=0.3)
    xs = [r["vehicles"] for r in results["inproc"]]
    ax[1].semilogx(xs, [r["ns_per_vehicle_tick"] for r in results["inproc"]], "o-")
    ax[1].set_xlabel("vehicles N")
    ax[1].set_ylabel("wall time per vehicle and 10 ms tick [ns]")
    ax[1].set_title("In-process cost per vehicle-tick (2 threads)")
    ax[1].grid(True, which="both", alpha=0.3)
    subs = results["substeps"]
    ax[2].plot([r["substeps"] for r in subs], [r["ns_per_tick"] for r in subs], "o-")
    ax[2].set_xlabel("RK4 sub-steps per 10 ms tick")
    ax[2].set_ylabel("wall time per tick [ns]")
    ax[2].set_title("One vehicle in-process vs integrator sub-steps")
    ax[2].grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(png)

    print("\n| vehicles | in-process RTF | ns per vehicle-tick |\n|---:|---:|---:|")
    for r in results["inproc"]:
        print(f"| {r['vehicles']} | {r['rtf']:.1f} | {r['ns_per_vehicle_tick']:.0f} |")
    print("\n| vehicles | DDS lockstep RTF |\n|---:|---:|")
    for r in results["dds"]:
        print(f"| {r['vehicles']} | {r['rtf']:.2f} |")
    print("\n| RK4 sub-steps | in-process RTF | ns per tick |\n|---:|---:|---:|")
    for r in subs:
        print(f"| {r['substeps']} | {r['rtf']:.0f} | {r['ns_per_tick']:.0f} |")
    if out_json:
        json.dump(results, open(out_json, "w"), indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
