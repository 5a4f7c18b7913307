#!/usr/bin/env python3
"""quadcosim.run of a scenario against `quadcosim run` of the same scenario, wall time per run.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_run.py build/bin/quadcosim [scenario] [repetitions]

Interleaves, per repetition: the CLI (`quadcosim run SCENARIO --out DIR --no-plots`, a process: its
start-up counts), the CLI's start-up alone (`quadcosim --version`), quadcosim.run(SCENARIO, out=DIR)
(the same files) and quadcosim.run(SCENARIO) (a temporary folder). Prints the median and the best of
each, and their ratios to the CLI's run with and without its start-up (cli - cli_startup).
"""
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import quadcosim


def main():
    cli = sys.argv[1]
    scenario = sys.argv[2] if len(sys.argv) > 2 else "scenarios/paper/altitude_step.yaml"
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 20
    work = tempfile.mkdtemp(prefix="quadcosim-bench-")
    times = {"cli": [], "cli_startup": [], "python_out": [], "python_no_out": []}
    try:
        quadcosim.run(scenario)  # warm-up: imports, page cache
        for i in range(reps):
            t0 = time.perf_counter()
            subprocess.run([cli, "run", scenario, "--out", f"{work}/cli{i}", "--no-plots"], check=True,
                           stdout=subprocess.DEVNULL)
            t1 = time.perf_counter()
            quadcosim.run(scenario, out=f"{work}/py{i}")
            t2 = time.perf_counter()
            quadcosim.run(scenario)
            t3 = time.perf_counter()
            subprocess.run([cli, "--version"], check=True, stdout=subprocess.DEVNULL)
            t4 = time.perf_counter()
            times["cli_startup"].append(t4 - t3)
            times["cli"].append(t1 - t0)
            times["python_out"].append(t2 - t1)
            times["python_no_out"].append(t3 - t2)
    finally:
        shutil.rmtree(work)
    cli_median = statistics.median(times["cli"])
    cli_run = cli_median - statistics.median(times["cli_startup"])
    print(f"{scenario}, {reps} repetitions each, interleaved")
    for name, t in times.items():
        m = statistics.median(t)
        print(f"  {name:14s} median {m * 1e3:8.2f} ms  best {min(t) * 1e3:8.2f} ms  "
              f"/ cli {m / cli_median:.2f}  / (cli - cli_startup) {m / cli_run:.2f}")


if __name__ == "__main__":
    main()
