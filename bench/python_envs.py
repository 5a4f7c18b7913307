#!/usr/bin/env python3
"""VectorHoverEnv's env-steps per second at several num_envs, and where the time of a step goes.

    PYTHONPATH=build/python nice -n 10 /usr/bin/python3 bench/python_envs.py [--envs 1 16 64 256 1024]
        [--steps 200] [--repetitions 5] [--threads 1]

An env-step is one control period (20 ms, two plant ticks) of one sub-env: env-steps per second =
steps x num_envs / wall seconds. Per num_envs, the median over --repetitions of:

  env          VectorHoverEnv.step(actions) (the hover action, no episode ends): all it does
  batch        Batch.step(omega_cmd=...) alone, the same rotor speeds: the C++ stepping and the call
  python       the rest: the action checks and the rotor speeds in numpy, the observation, reward and
               termination (Batch.env_terms, one pass in C++) (measured as those calls alone)

and the share of `python` in `env`. --threads: the Batch's worker threads (numbers unchanged).
"""
import argparse
import statistics
import time

import numpy as np

from quadcosim.envs import VectorHoverEnv


def timed(fn, steps: int) -> float:
    t0 = time.perf_counter()
    for _ in range(steps):
        fn()
    return time.perf_counter() - t0


def measure(n: int, steps: int, repetitions: int, threads: int):
    env = VectorHoverEnv(n, max_episode_steps=10 ** 9, threads=threads)
    env.reset(seed=0)
    e = env.unwrapped._e
    actions = e.hover_action.astype(np.float32)
    a, omega = e.command(actions)

    def python_part():
        e.command(actions)
        e.terms(a)

    out = {"env": [], "batch": [], "python": []}
    for _ in range(repetitions):
        out["env"].append(timed(lambda: env.step(actions), steps))
        out["batch"].append(timed(lambda: e.batch.step(omega_cmd=omega), steps))
        out["python"].append(timed(python_part, steps))
    return {k: n * steps / statistics.median(v) for k, v in out.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--envs", type=int, nargs="+", default=[1, 16, 64, 256, 1024])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    print(f"{'num_envs':>8} {'env steps/s':>12} {'batch steps/s':>14} {'python steps/s':>15} {'python share':>13}")
    for n in args.envs:
        r = measure(n, args.steps, args.repetitions, args.threads)
        share = (1 / r["python"]) / (1 / r["env"])
        print(f"{n:8d} {r['env']:12.0f} {r['batch']:14.0f} {r['python']:15.0f} {100 * share:12.0f} %")


if __name__ == "__main__":
    main()
