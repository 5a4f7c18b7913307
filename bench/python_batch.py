#!/usr/bin/env python3
"""quadcosim.Batch stepped from Python against the C++ in-process swarm, in vehicle-steps per second.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_batch.py [--vehicles 1000] [--periods 250]
        [--repetitions 7] [--threads 2] [--scenario scenarios/swarm/grid_takeoff.yaml] [--only NAME]

A vehicle-step is one plant tick of one vehicle (the plant's outputs, the controller's step on
control ticks, the latch and the integration): vehicle-steps per second = plant ticks x vehicles /
wall seconds, the same count for every case. Interleaved, per repetition, each over the same
simulated time (--periods control periods):

  swarm        sim::Swarm::run_ticks in blocks of 100 ticks, as `quadcosim bench --only swarm_inproc`
               (the same library code, called from the module with the GIL released; controllers fly)
  swarm_b2     the same in blocks of 2 ticks (one control period: the stepping pattern of Batch.step())
  batch        Batch.step() once per control period from a Python loop (controllers fly)
  batch_p50    Batch.step(periods=50): 50 control periods per call (controllers fly)
  batch_cmd    Batch.step(omega_cmd=...) and reading Batch.p once per control period: the rotor
               commands come from Python, the controllers are bypassed (no controller work: it
               measures what an RL loop pays per step besides its policy, not the same work as swarm)
  batch_lean   the same on Batch(plant_only=True): no controller nodes or buses, the plants' state in a
               contiguous array (the same numbers as batch_cmd's vehicles)

Prints the median and best of each and the ratios of batch, batch_p50, batch_cmd and batch_lean to swarm.
--only NAME runs one case once (for valgrind --tool=callgrind: compare two --periods to remove start-up).
"""
import argparse
import statistics
import time

import numpy as np

import quadcosim
from quadcosim import _quadcosim


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--vehicles", type=int, default=1000)
    ap.add_argument("--periods", type=int, default=250, help="control periods per measurement")
    ap.add_argument("--repetitions", type=int, default=7)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenario", default="scenarios/swarm/grid_takeoff.yaml")
    ap.add_argument("--only", choices=["swarm", "swarm_b2", "batch", "batch_p50", "batch_cmd", "batch_lean"])
    o = ap.parse_args()
    sc = quadcosim.load_scenario(o.scenario)
    n, periods = o.vehicles, o.periods
    batch = quadcosim.Batch(sc, n, threads=o.threads)
    lean = quadcosim.Batch(sc, n, threads=o.threads, plant_only=True)
    tps = batch.ticks_per_step
    ticks = periods * tps
    warmup = 10
    cmd = np.repeat(batch.vehicle_params["hover_omega_rad_s"][:, None], 4, axis=1)
    yaml, source = sc.yaml(), sc.source

    def swarm(block):
        return _quadcosim._swarm_wall_s(yaml, source, n, ticks, o.threads, block, warmup * tps)

    def run_batch():
        batch.reset()
        batch.step(periods=warmup)
        t0 = time.perf_counter()
        for _ in range(periods):
            batch.step()
        return time.perf_counter() - t0

    def run_batch_p50():
        batch.reset()
        batch.step(periods=warmup)
        t0 = time.perf_counter()
        left = periods
        while left > 0:
            batch.step(periods=min(50, left))
            left -= 50
        return time.perf_counter() - t0

    def run_batch_cmd(b=batch):
        b.reset()
        if b.plant_only:
            b.step(omega_cmd=cmd, periods=warmup)
        else:
            b.step(periods=warmup)
        t0 = time.perf_counter()
        for _ in range(periods):
            b.step(omega_cmd=cmd)
            b.p
        return time.perf_counter() - t0

    cases = {"swarm": lambda: swarm(100), "swarm_b2": lambda: swarm(tps), "batch": run_batch,
             "batch_p50": run_batch_p50, "batch_cmd": run_batch_cmd, "batch_lean": lambda: run_batch_cmd(lean)}
    if o.only:
        wall = cases[o.only]()
        print(f"{o.only}: {n} vehicles x {ticks} ticks in {wall:.3f} s: {n * ticks / wall / 1e6:.3f} M vehicle-steps/s")
        return
    walls = {k: [] for k in cases}
    for _ in range(o.repetitions):
        for k, f in cases.items():
            walls[k].append(f())
    rate = {k: [n * ticks / w for w in ws] for k, ws in walls.items()}
    print(f"{o.scenario}: {n} vehicles, {periods} control periods ({ticks} plant ticks) per measurement, "
          f"{o.threads} threads, {o.repetitions} repetitions interleaved")
    print(f"{'case':10s} {'median':>22s} {'best':>22s}")
    for k, r in rate.items():
        print(f"{k:10s} {statistics.median(r) / 1e6:10.3f} M vehicle-steps/s {max(r) / 1e6:10.3f} M vehicle-steps/s")
    for k in ("batch", "batch_p50", "batch_cmd", "batch_lean"):
        print(f"{k} / swarm: median {statistics.median(rate[k]) / statistics.median(rate['swarm']):.2f}, "
              f"best {max(rate[k]) / max(rate['swarm']):.2f}; / swarm_b2: median "
              f"{statistics.median(rate[k]) / statistics.median(rate['swarm_b2']):.2f}")


if __name__ == "__main__":
    main()
