#!/usr/bin/env python3
"""Learns to hover and recover with the rotor speeds alone: a compact PPO on quadcosim.envs.VectorHoverEnv.

    PYTHONPATH=build/python nice -n 10 /usr/bin/python3 examples/learn_hover.py [--iterations 400]
        [--minutes M] [--envs 64] [--seed 0] [--eval-episodes 100] [--out results/learn_hover] [--action KIND]

The task: hold (0, 0, 2) m from a random start up to 1 m off on every axis, up to 30 deg off in roll,
pitch and yaw, moving at up to 0.2 m/s per axis and turning at up to 0.2 rad/s per axis
(quadcosim.starts.RECOVER_START), the rotors spinning at hover speed. The policy commands the four
rotor speeds at 50 Hz (the env's normalised action in [-1, 1]); no controller flies.

PPO (Schulman et al. 2017) in a few lines of torch: the clipped surrogate objective, generalised
advantage estimation (GAE, with the value of the last observation bootstrapped when an episode is
cut by its time limit, and zero after a crash), a value function, observation normalisation (running
mean and variance, frozen during a rollout), a Gaussian policy whose samples the env clips to
[-1, 1] (its mean starts at the hover command). Deterministic: the same command gives the same policy
on the same machine and software (torch in one thread, deterministic algorithms; the simulation's
numbers do not depend on its threads). --minutes stops early when the wall time runs out, which
depends on the machine: without it the iterations alone decide.

After training it evaluates the policy's mean action on --eval-episodes held-out starts (seeds
1_000_000 + i, never used in training) and prints the success rate. Success: never terminated (no
crash, never out of the 2 m box), and 5 s after the start within 0.1 m of the target and below
0.2 m/s. Writes OUT/policy.pt (the weights, the observation statistics and the configuration),
OUT/learning.json (the learning curve and the evaluation) and OUT/learning.png (the curve and a few
evaluated recoveries). Needs torch (Debian: python3-torch) and, for the plot, matplotlib.
"""

import argparse
import json
import math
import os
import sys
import time
from typing import Any, Dict, List, Optional

import numpy as np

from quadcosim.envs import VectorHoverEnv
from quadcosim.starts import RECOVER_START

# A trimmed hover at (0, 0, 2) m with the paper's vehicle, no noise: the target of every episode.
SCENARIO: Dict[str, Any] = {
    "name": "hover_recover",
    "description": "learn_hover: hold (0, 0, 2) m",
    "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
    "initial": {"position_m": [0.0, 0.0, 2.0], "hover": True},
    "controller": {"mode": "attitude", "z_des": 2.0},
}

REWARD_WEIGHTS = {"position": 2.0, "velocity": 0.2}  # rate and action: the env's 0.01 each
EPISODE_S = 5.0  # training episodes and evaluations last 5 s (250 steps at 50 Hz)
SUCCESS_POSITION_M = 0.1
SUCCESS_SPEED_M_S = 0.2
EVAL_SEED_BASE = 1_000_000


def defaults() -> Dict[str, Any]:
    """The configuration train() uses unless told otherwise."""
    return dict(envs=64, rollout_steps=64, iterations=400, epochs=10, minibatches=4, lr=1e-3, gamma=0.99,
                gae_lambda=0.95, clip=0.2, value_coef=0.5, entropy_coef=0.0, max_grad_norm=0.5, hidden=64,
                log_std_init=-1.6, reward_scale=0.1, anneal_lr=True, seed=0, minutes=None, sim_threads=1,
                env_kwargs={})


def make_env(num_envs: int, sim_threads: int = 1, **env_kwargs: Any) -> VectorHoverEnv:
    """The training and evaluation env: SCENARIO, RECOVER_START, 5 s episodes, the env's reward with
    REWARD_WEIGHTS (position and velocity weighed twice the env's defaults: with those the policies
    settled farther from the target) and a termination penalty of 200 (with the default 10, ending an
    episode early costs less than flying back from a far start), same-step auto-reset (the last
    observation of an ended episode in info["final_obs"]). env_kwargs go to VectorHoverEnv (e.g.
    action=..., reward_weights=...)."""
    kw = dict(scenario=SCENARIO, random_start=RECOVER_START, max_episode_steps=int(round(EPISODE_S * 50)),
              reward_weights=REWARD_WEIGHTS, termination_penalty=200.0, autoreset_mode="same_step",
              threads=sim_threads)
    kw.update(env_kwargs)
    return VectorHoverEnv(num_envs, **kw)


def _torch():
    try:
        import torch
    except ImportError:
        sys.exit("learn_hover: needs torch (Debian: sudo apt-get install python3-torch; scripts/install-deps.sh "
                 "installs it)")
    return torch


def hover_offset(env: VectorHoverEnv) -> np.ndarray:
    """Where the policy's mean starts: the action that commands hover at the env's action level (for
    the rotor speeds, the envs' default, the first vehicle's hover speed on every rotor)."""
    return env.hover_action[0].astype(np.float32)


class RunningNorm:
    """Running mean and variance of observations (parallel Welford), float64."""

    def __init__(self, size: int):
        self.mean = np.zeros(size)
        self.var = np.ones(size)
        self.count = 1e-4

    def update(self, x: np.ndarray) -> None:
        x = np.asarray(x, dtype=np.float64).reshape(-1, self.mean.size)
        m, v, c = x.mean(axis=0), x.var(axis=0), x.shape[0]
        delta, total = m - self.mean, self.count + c
        self.mean = self.mean + delta * c / total
        self.var = (self.var * self.count + v * c + delta ** 2 * self.count * c / total) / total
        self.count = total

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return np.clip((x - self.mean) / np.sqrt(self.var + 1e-8), -10.0, 10.0).astype(np.float32)

    def state(self) -> Dict[str, Any]:
        return {"mean": self.mean.tolist(), "var": self.var.tolist(), "count": self.count}


def make_policy(obs_size: int, act_size: int, hidden: int, log_std_init: float, offset: np.ndarray):
    torch = _torch()
    nn = torch.nn

    class ActorCritic(nn.Module):
        """Gaussian policy (mean = offset + MLP(obs), state-independent std) and a value MLP."""

        def __init__(self):
            super().__init__()
            self.pi = nn.Sequential(nn.Linear(obs_size, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(),
                                    nn.Linear(hidden, act_size))
            self.v = nn.Sequential(nn.Linear(obs_size, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(),
                                   nn.Linear(hidden, 1))
            for net, gain in ((self.pi, 0.01), (self.v, 1.0)):
                for i, layer in enumerate(m for m in net if isinstance(m, nn.Linear)):
                    nn.init.orthogonal_(layer.weight, gain if i == 2 else math.sqrt(2))
                    nn.init.zeros_(layer.bias)
            self.log_std = nn.Parameter(torch.full((act_size,), float(log_std_init)))
            self.register_buffer("offset", torch.as_tensor(offset, dtype=torch.float32))

        def mean(self, obs):
            return self.offset + self.pi(obs)

        def dist(self, obs):
            return torch.distributions.Normal(self.mean(obs), self.log_std.exp())

        def value(self, obs):
            return self.v(obs).squeeze(-1)

    return ActorCritic()


def _setup_torch(seed: int):
    torch = _torch()
    torch.manual_seed(seed)
    torch.set_num_threads(1)  # the same reductions in the same order every run
    torch.use_deterministic_algorithms(True)
    return torch


def train(config: Optional[Dict[str, Any]] = None, log=print) -> Dict[str, Any]:
    """PPO with `config` (keys of defaults()). Returns {"policy", "norm", "history", "config", "wall_s",
    "env_steps"}; history: one dict per iteration (mean return and length of the episodes that ended
    in it, losses)."""
    cfg = dict(defaults(), **(config or {}))
    torch = _setup_torch(cfg["seed"])
    env = make_env(cfg["envs"], cfg["sim_threads"], **cfg["env_kwargs"])
    n, T = cfg["envs"], cfg["rollout_steps"]
    obs_size, act_size = env.single_observation_space.shape[0], env.single_action_space.shape[0]
    offset = hover_offset(env)
    policy = make_policy(obs_size, act_size, cfg["hidden"], cfg["log_std_init"], offset)
    opt = torch.optim.Adam(policy.parameters(), lr=cfg["lr"], eps=1e-5)
    norm = RunningNorm(obs_size)
    raw, _ = env.reset(seed=cfg["seed"] * 100_003)  # sub-env i: seed * 100003 + i
    norm.update(raw)
    ep_return, ep_len = np.zeros(n), np.zeros(n, dtype=np.int64)
    history: List[Dict[str, Any]] = []
    t0 = time.perf_counter()
    env_steps = 0
    for it in range(cfg["iterations"]):
        if cfg["minutes"] is not None and time.perf_counter() - t0 > 60 * cfg["minutes"]:
            log(f"stopping after {it} iterations: --minutes {cfg['minutes']} used")
            break
        if cfg["anneal_lr"]:  # linearly to 0 over the iterations: finer steps as the policy settles
            for g in opt.param_groups:
                g["lr"] = cfg["lr"] * (1.0 - it / cfg["iterations"])
        buf_obs = np.zeros((T, n, obs_size), np.float32)
        buf_act = np.zeros((T, n, act_size), np.float32)
        buf_logp, buf_val, buf_rew = (np.zeros((T, n), np.float32) for _ in range(3))
        buf_done = np.zeros((T, n), bool)  # the episode ended after this step (no bootstrap across it)
        raws = []
        finished_returns, finished_lengths, crashes = [], [], 0
        for t in range(T):
            o = norm(raw)
            with torch.no_grad():
                ot = torch.as_tensor(o)
                d = policy.dist(ot)
                a = d.sample()
                logp = d.log_prob(a).sum(-1)
                v = policy.value(ot)
            a_np = a.numpy()
            raw, rew, term, trunc, info = env.step(a_np)
            raws.append(raw)
            ep_return += rew
            rew = rew * cfg["reward_scale"]
            if np.any(trunc & ~term):
                # Cut by the time limit: the value of where it stood is the rest of its return.
                cut = np.flatnonzero(trunc & ~term)
                with torch.no_grad():
                    v_last = policy.value(torch.as_tensor(norm(info["final_obs"][cut]))).numpy()
                rew = rew.copy()
                rew[cut] += cfg["gamma"] * v_last
            done = term | trunc
            buf_obs[t], buf_act[t], buf_logp[t], buf_val[t], buf_rew[t], buf_done[t] = o, a_np, logp, v, rew, done
            ep_len += 1
            for i in np.flatnonzero(done):
                finished_returns.append(float(ep_return[i]))
                finished_lengths.append(int(ep_len[i]))
                crashes += int(term[i])
            ep_return[done], ep_len[done] = 0.0, 0
        env_steps += T * n
        with torch.no_grad():
            last_v = policy.value(torch.as_tensor(norm(raw))).numpy()
        adv = np.zeros((T, n), np.float32)
        gae = np.zeros(n, np.float32)
        for t in reversed(range(T)):
            next_v = last_v if t == T - 1 else buf_val[t + 1]
            live = 1.0 - buf_done[t]
            delta = buf_rew[t] + cfg["gamma"] * next_v * live - buf_val[t]
            gae = delta + cfg["gamma"] * cfg["gae_lambda"] * live * gae
            adv[t] = gae
        ret = adv + buf_val
        b_obs, b_act = torch.as_tensor(buf_obs.reshape(T * n, -1)), torch.as_tensor(buf_act.reshape(T * n, -1))
        b_logp, b_adv, b_ret = (torch.as_tensor(x.reshape(-1)) for x in (buf_logp, adv, ret))
        size = T * n // cfg["minibatches"]
        for _ in range(cfg["epochs"]):
            perm = torch.randperm(T * n)
            for k in range(cfg["minibatches"]):
                idx = perm[k * size:(k + 1) * size]
                d = policy.dist(b_obs[idx])
                logp = d.log_prob(b_act[idx]).sum(-1)
                ratio = (logp - b_logp[idx]).exp()
                a_mb = b_adv[idx]
                a_mb = (a_mb - a_mb.mean()) / (a_mb.std() + 1e-8)
                pg_loss = -torch.min(ratio * a_mb, ratio.clamp(1 - cfg["clip"], 1 + cfg["clip"]) * a_mb).mean()
                v_loss = 0.5 * ((policy.value(b_obs[idx]) - b_ret[idx]) ** 2).mean()
                entropy = d.entropy().sum(-1).mean()
                loss = pg_loss + cfg["value_coef"] * v_loss - cfg["entropy_coef"] * entropy
                opt.zero_grad()
                loss.backward()
                torch.nn.utils.clip_grad_norm_(policy.parameters(), cfg["max_grad_norm"])
                opt.step()
        norm.update(np.concatenate(raws))
        h = {"iteration": it + 1, "env_steps": env_steps, "wall_s": time.perf_counter() - t0,
             "episodes": len(finished_returns),
             "mean_return": float(np.mean(finished_returns)) if finished_returns else None,
             "mean_length": float(np.mean(finished_lengths)) if finished_lengths else None,
             "terminated": crashes, "pg_loss": float(pg_loss), "v_loss": float(v_loss),
             "std": float(policy.log_std.exp().mean())}
        history.append(h)
        if (it + 1) % 10 == 0 or it == 0:
            mr = "-" if h["mean_return"] is None else f"{h['mean_return']:8.1f}"
            log(f"iter {it + 1:4d}  steps {env_steps:8d}  {h['wall_s']:6.1f} s  return {mr}  "
                f"episodes {h['episodes']:3d} (terminated {crashes:3d})  std {h['std']:.3f}")
    return {"policy": policy, "norm": norm, "history": history, "config": cfg,
            "wall_s": time.perf_counter() - t0, "env_steps": env_steps}


def policy_action(policy, norm: RunningNorm, raw: np.ndarray) -> np.ndarray:
    """The policy's mean action for raw observations (what evaluation and deployment fly)."""
    torch = _torch()
    with torch.no_grad():
        return policy.mean(torch.as_tensor(norm(raw))).numpy()


def evaluate(act, episodes: int = 100, seed_base: int = EVAL_SEED_BASE, record: int = 0,
             env_kwargs: Optional[Dict[str, Any]] = None) -> Dict[str, Any]:
    """Flies `act` (raw observations (n, 18) -> actions) from `episodes` starts (seeds seed_base + i) for
    EPISODE_S. Returns success_rate and per-episode arrays: success, terminated, final position error
    [m] and speed [m/s], return; and `record` trajectories (t, position error) of the first episodes."""
    env = make_env(episodes, 1, **(env_kwargs or {}))
    # Next-step auto-reset would restart an ended episode; same-step with a mask of ended ones is simpler:
    raw, _ = env.reset(seed=seed_base)
    steps = env._e.max_episode_steps
    alive = np.ones(episodes, bool)
    returns = np.zeros(episodes)
    traj = np.zeros((steps + 1, min(record, episodes), 3))
    traj[0] = raw[:record, 0:3]
    final = raw.copy()
    for k in range(steps):
        raw, rew, term, trunc, info = env.step(np.asarray(act(raw), dtype=np.float64))
        returns += np.where(alive, rew, 0.0)
        now = np.where((term | trunc)[:, None], info["final_obs"], raw)
        alive &= ~term
        final = np.where(alive[:, None], now, final)
        traj[k + 1] = np.where(alive[:record, None], now[:record, 0:3], np.nan)
    err = np.linalg.norm(final[:, 0:3], axis=1)
    speed = np.linalg.norm(final[:, 3:6], axis=1)
    success = alive & (err < SUCCESS_POSITION_M) & (speed < SUCCESS_SPEED_M_S)
    return {"success_rate": float(success.mean()), "success": success, "terminated": ~alive, "error_m": err,
            "speed_m_s": speed, "return": returns, "t": np.arange(steps + 1) * env.batch.dt, "trajectories": traj}


def plot(path: str, history: List[Dict[str, Any]], ev: Dict[str, Any], title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a0, a1) = plt.subplots(1, 2, figsize=(11, 4.2))
    xs = [h["env_steps"] / 1e6 for h in history if h["mean_return"] is not None]
    ys = [h["mean_return"] for h in history if h["mean_return"] is not None]
    a0.plot(xs, ys)
    a0.set_xlabel("environment steps [millions]")
    a0.set_ylabel("mean return of the episodes ended")
    a0.set_title("learning curve")
    a0.grid(True, alpha=0.3)
    t, traj = ev["t"], ev["trajectories"]
    for i in range(traj.shape[1]):
        a1.plot(t, np.linalg.norm(traj[:, i], axis=1), lw=1)
    a1.axhline(SUCCESS_POSITION_M, color="k", ls="--", lw=0.8, label=f"{SUCCESS_POSITION_M} m")
    a1.set_xlabel("t [s]")
    a1.set_ylabel("distance to the target [m]")
    a1.set_yscale("log")
    a1.set_title(f"{traj.shape[1]} evaluated recoveries (held-out starts)")
    a1.legend()
    a1.grid(True, alpha=0.3, which="both")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    d = defaults()
    ap.add_argument("--iterations", type=int, default=d["iterations"], help="PPO iterations (default %(default)s)")
    ap.add_argument("--minutes", type=float, default=None, help="stop earlier when this wall time is used")
    ap.add_argument("--envs", type=int, default=d["envs"], help="parallel episodes (default %(default)s)")
    ap.add_argument("--seed", type=int, default=d["seed"])
    ap.add_argument("--eval-episodes", type=int, default=100)
    ap.add_argument("--sim-threads", type=int, default=1, help="threads stepping the vehicles (numbers unchanged)")
    ap.add_argument("--out", default="results/learn_hover")
    ap.add_argument("--action", default=None,
                    help="the envs' action= (default: theirs, the normalised rotor speeds); passed through as it is")
    args = ap.parse_args(argv)
    if args.iterations < 1 or args.envs < 1 or args.eval_episodes < 1:
        ap.error("--iterations, --envs and --eval-episodes must be at least 1")
    torch = _torch()
    os.makedirs(args.out, exist_ok=True)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"torch {torch.__version__}, load average {load:.2f} "
          f"on {os.cpu_count()} CPUs")
    env_kwargs = {} if args.action is None else {"action": args.action}
    r = train({"iterations": args.iterations, "envs": args.envs, "seed": args.seed, "minutes": args.minutes,
               "sim_threads": args.sim_threads, "env_kwargs": env_kwargs})
    policy, norm = r["policy"], r["norm"]
    t0 = time.perf_counter()
    ev = evaluate(lambda o: policy_action(policy, norm, o), args.eval_episodes, record=8, env_kwargs=env_kwargs)
    eval_s = time.perf_counter() - t0
    load_end = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    n_ok = int(ev["success"].sum())
    print(f"trained {len(r['history'])} iterations, {r['env_steps']} env steps in {r['wall_s']:.1f} s wall "
          f"({r['env_steps'] / r['wall_s']:.0f} steps/s incl. updates; load average {load:.2f} -> {load_end:.2f})")
    err_mm = 1000 * np.percentile(ev["error_m"], [50, 90, 100])
    print(f"success rate {100 * ev['success_rate']:.1f} % ({n_ok}/{args.eval_episodes} held-out starts: "
          f"within {SUCCESS_POSITION_M} m and below {SUCCESS_SPEED_M_S} m/s at {EPISODE_S:g} s, never terminated); "
          f"terminated {int(ev['terminated'].sum())}; distance to the target at {EPISODE_S:g} s: median "
          f"{err_mm[0]:.0f} mm, 90 % {err_mm[1]:.0f} mm, max {err_mm[2]:.0f} mm; speed max "
          f"{ev['speed_m_s'].max():.3f} m/s; evaluation {eval_s:.1f} s")
    torch.save({"state_dict": policy.state_dict(), "obs_norm": norm.state(), "config": r["config"],
                "scenario": SCENARIO, "random_start": RECOVER_START}, os.path.join(args.out, "policy.pt"))
    with open(os.path.join(args.out, "learning.json"), "w") as f:
        json.dump({"history": r["history"], "wall_s": r["wall_s"], "env_steps": r["env_steps"],
                   "load_average": [load, load_end], "success_rate": ev["success_rate"],
                   "eval_episodes": args.eval_episodes, "terminated": int(ev["terminated"].sum()),
                   "error_m": ev["error_m"].tolist(), "speed_m_s": ev["speed_m_s"].tolist()}, f, indent=1)
    try:
        plot(os.path.join(args.out, "learning.png"), r["history"], ev,
             f"PPO hover-and-recover: {100 * ev['success_rate']:.0f} % success, trained in {r['wall_s']:.0f} s")
    except ImportError:
        print("no matplotlib: learning.png not written (Debian: python3-matplotlib)")
    print(f"wrote {args.out}/policy.pt, learning.json, learning.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
