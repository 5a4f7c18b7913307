#!/usr/bin/env python3
"""Environment steps per second at each action level: quadcosim.Batch(plant_only=True, action=LEVEL)
stepped from Python, and the vectorised env VectorHoverEnv(action=LEVEL) with its observation and
reward, on --threads worker threads.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_levels.py [--envs 4096] [--steps 200]
        [--repetitions 5] [--threads 2] [--levels rotor_speeds,ctbr]

An env-step is one control period of one vehicle (ticks_per_step plant ticks: 2 at the default
100 Hz plant and 50 Hz control): env-steps per second = steps x envs / wall seconds. Cases, interleaved
per repetition:

  batch_LEVEL   Batch.step(command) with a fixed (envs, 4) command array, nothing read back: the
                simulator's own cost per env-step (the inner loops run on every plant tick above
                rotor speeds)
  env_LEVEL     VectorHoverEnv.step(actions): action mapping, Batch.step, observation (18 floats),
                reward and termination in numpy, as a learner calls it (no policy)

Prints the median and best of each case.
"""
import argparse
import statistics
import time

import numpy as np

import quadcosim
from quadcosim.envs import VectorHoverEnv


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--envs", type=int, default=4096)
    ap.add_argument("--steps", type=int, default=200, help="env steps per measurement")
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--levels", default="rotor_speeds,ctbr")
    o = ap.parse_args()
    levels = o.levels.split(",")
    n = o.envs
    cases = {}
    for level in levels:
        env = VectorHoverEnv(n, threads=o.threads, action=level, max_episode_steps=10**9)
        env.reset(seed=0)
        hover = np.repeat(env._e.hover_action[:1], n, axis=0).astype(np.float32)
        _, command = env._e.command(hover)
        batch = quadcosim.Batch(env.batch.scenario, n, threads=o.threads, plant_only=True, action=level)

        def run_batch(batch=batch, command=command):
            batch.reset()
            t0 = time.perf_counter()
            for _ in range(o.steps):
                batch.step(command)
            return time.perf_counter() - t0

        def run_env(env=env, hover=hover):
            env.reset(seed=0)
            t0 = time.perf_counter()
            for _ in range(o.steps):
                env.step(hover)
            return time.perf_counter() - t0

        cases[f"batch_{level}"] = run_batch
        cases[f"env_{level}"] = run_env
    results = {name: [] for name in cases}
    for _ in range(o.repetitions):
        for name, run in cases.items():
            results[name].append(o.steps * n / run())
    print(f"{n} envs, {o.steps} steps per measurement, {o.repetitions} repetitions, {o.threads} threads "
          "(env-steps/s: one control period of one vehicle)")
    for name, r in results.items():
        print(f"  {name:22s} median {statistics.median(r):14,.0f}   best {max(r):14,.0f}")


if __name__ == "__main__":
    main()
