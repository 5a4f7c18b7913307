"""The n episodes on one Batch behind every env of envs.py: the default scenarios, the actions mapped
to commands at the env's level, the resets (seeds, randomised vehicles, random starts), and the
observations, rewards and termination (computed in C++, Batch.env_terms). The formulas and units are
in envs.py's docstring."""

import math
import numbers
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._quadcosim import ConfigError
from .action_levels import ACTION_LEVELS, action_ranges as _action_ranges
from .batch import Batch
from .spaces import Box
from .starts import check_start, draw_start

OBS_SIZE = 18
ACTION_SIZE = 4  # a quadrotor's; an env's own is action_space.shape (the rotor count N at rotor_speeds)

# A trimmed hover 1 m above the ground with the paper's vehicle, no noise (the default of HoverEnv).
HOVER_SCENARIO: Dict[str, Any] = {
    "name": "hover_env",
    "description": "HoverEnv: trimmed hover at (0, 0, 1) m",
    "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
    "initial": {"position_m": [0.0, 0.0, 1.0], "hover": True},
    "controller": {"mode": "attitude", "z_des": 1.0},
}

# A circle of radius 1 m at 1 m, 10 s per lap, spun up over 2 s, started trimmed in hover at its start
# point (the default of TrackingEnv).
TRACKING_SCENARIO: Dict[str, Any] = {
    "name": "tracking_env",
    "description": "TrackingEnv: circle r = 1 m, period 10 s at 1 m",
    "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 20},
    "initial": {"position_m": [1.0, 0.0, 1.0], "hover": True},
    "controller": {"mode": "position"},
    "trajectory": {"kind": "circle", "centre_m": [0, 0], "altitude_m": 1, "radius_m": 1, "period_s": 10,
                   "ramp_s": 2, "yaw_mode": "fixed"},
}

_REWARD_WEIGHTS = {"position": 1.0, "velocity": 0.1, "rate": 0.01, "action": 0.01}


class _Episodes:
    """n episodes on one Batch: actions, observations, rewards, termination (shared by the envs)."""

    def __init__(self, n: int, tracking: bool, scenario: Any, trajectory: Optional[Dict[str, Any]],
                 target: Any, max_episode_steps: int, max_position_error_m: float, crash_altitude_m: float,
                 max_tilt_rad: float, max_speed_m_s: float, max_rate_rad_s: float,
                 reward_weights: Optional[Dict[str, float]], termination_penalty: float,
                 randomize: Optional[Dict[str, Any]], threads: Optional[int],
                 random_start: Optional[Dict[str, Any]] = None, action: str = "rotor_speeds"):
        if action not in ACTION_LEVELS:
            raise ValueError(f"action = {action!r}: expected one of {', '.join(ACTION_LEVELS)}")
        self.action = action
        if scenario is None:
            scenario = TRACKING_SCENARIO if tracking else HOVER_SCENARIO
        sections = {"trajectory": trajectory} if trajectory is not None else None
        threads = 1 if threads is None and n < 64 else threads
        try:
            # The actions are the rotor speeds: the plants alone (much faster per step, the same numbers).
            self.batch = Batch(scenario, n, seeds=0, threads=threads, plant_only=True, action=action,
                               _sections=sections)
        except ConfigError as e:
            if "plant_only" not in str(e):
                raise
            # Message faults or external dynamics need the whole vehicle with its bus.
            self.batch = Batch(scenario, n, seeds=0, threads=threads, action=action, _sections=sections)
        if tracking and not self.batch.tracks_trajectory:
            raise ValueError(f"TrackingEnv: scenario '{self.batch.scenario.name}' has no trajectory: section; give "
                             "one with trajectory={...} (the keys of a scenario's trajectory:, docs/scenarios.md)")
        self.n = n
        self.tracking = tracking
        if isinstance(max_episode_steps, bool) or not isinstance(max_episode_steps, numbers.Integral) \
                or max_episode_steps < 1:
            raise ValueError(f"max_episode_steps = {max_episode_steps!r}: expected an integer >= 1")
        self.max_episode_steps = int(max_episode_steps)
        self.max_position_error_m = float(max_position_error_m)
        self.crash_altitude_m = float(crash_altitude_m)
        self.cos_max_tilt = math.cos(float(max_tilt_rad))
        self.termination_penalty = float(termination_penalty)
        self.limits = {"crash_altitude_m": self.crash_altitude_m, "cos_max_tilt": self.cos_max_tilt,
                       "max_position_error_m": self.max_position_error_m,
                       "termination_penalty": self.termination_penalty}
        unknown = set(reward_weights or {}) - set(_REWARD_WEIGHTS)
        if unknown:
            raise ValueError(f"reward_weights: unknown {sorted(unknown)}; expected {sorted(_REWARD_WEIGHTS)}")
        self.weights = dict(_REWARD_WEIGHTS, **(reward_weights or {}))
        self.randomize = self._check_randomize(randomize)
        self.start_half_widths = check_start(random_start)
        self.home_p, self.home_q = self.batch.p, self.batch.q  # the scenario's initial position and attitude
        self.default_target = None if target is None else np.broadcast_to(np.asarray(target, float), (3,)).copy()
        # The position each hover episode holds: the target given, else the scenario's initial position.
        self.target = self.batch.p if self.default_target is None else np.repeat(self.default_target[None], n, 0)
        self.steps = np.zeros(n, dtype=np.int64)
        self.ended = np.ones(n, dtype=bool)  # before the first reset
        self._refresh_vehicles()
        bound = np.concatenate([np.full(3, self.max_position_error_m), np.full(3, float(max_speed_m_s)),
                                np.ones(9), np.full(3, float(max_rate_rad_s))])
        self.observation_space = Box(-bound, bound, dtype=np.float32)
        self.action_space = Box(-1.0, 1.0, (self.action_size,), dtype=np.float32)

    @staticmethod
    def _check_randomize(randomize: Optional[Dict[str, Any]]) -> Optional[Dict[str, Tuple[np.ndarray, np.ndarray]]]:
        if not randomize:
            return None
        out = {}
        for key, bounds in randomize.items():
            try:
                low, high = bounds
                low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
            except (TypeError, ValueError):
                raise ValueError(f"randomize[{key!r}]: expected (low, high), got {bounds!r}") from None
            if low.shape != high.shape or not np.all(np.isfinite(low)) or not np.all(np.isfinite(high)) \
                    or np.any(low > high):
                raise ValueError(f"randomize[{key!r}]: expected finite low <= high of one shape, got {bounds!r}")
            out[key] = (low, high)
        return out

    def _refresh_vehicles(self) -> None:
        self.lo, self.hi, hover = _action_ranges(self.action, self.batch.vehicle_params)
        self.hover_action = 2 * (hover - self.lo) / (self.hi - self.lo) - 1
        self.action_size = self.lo.shape[1]  # 4, or the rotor count at rotor_speeds

    def draw(self, rng: np.random.Generator) -> Tuple[int, Optional[Dict[str, Any]]]:
        """An episode's noise seed and vehicle keys (uniform within the randomisation ranges)."""
        seed = int(rng.integers(0, 2**63))
        if self.randomize is None:
            return seed, None
        keys = {}
        for k, (low, high) in self.randomize.items():
            v = rng.uniform(low, high)
            keys[k] = v.tolist() if isinstance(v, np.ndarray) else float(v)
        return seed, keys

    def reset(self, indices: np.ndarray, rngs: Sequence[np.random.Generator], targets: Optional[np.ndarray]) -> None:
        if targets is not None:
            self.target[indices] = targets
        elif self.default_target is None and not self.tracking:
            self.target[indices] = self.home_p[indices]  # the scenario's initial position
        seeds, vehicles, starts = [], [], []
        for i in indices:
            s, v = self.draw(rngs[i])
            seeds.append(s)
            vehicles.append(v)
            if self.start_half_widths is not None:
                # Around the position held (hover) or the scenario's initial position (tracking).
                starts.append(draw_start(rngs[i], self.start_half_widths,
                                         self.home_p[i] if self.tracking else self.target[i], self.home_q[i]))
        states = None if not starts else {k: np.array([st[k] for st in starts]) for k in ("p", "v", "q", "w")}
        self.batch.reset(list(indices), seeds=seeds, vehicles=vehicles if self.randomize else None, states=states)
        if self.randomize:
            self._refresh_vehicles()
        self.steps[indices] = 0
        self.ended[indices] = False

    def command(self, action: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """The clipped actions and the commands they map to at the env's level."""
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (self.n, self.action_size):
            raise ValueError(f"action: expected shape {(self.action_size,) if self.n == 1 else (self.n, self.action_size)}, "
                             f"got {np.shape(action)}")
        if not np.all(np.isfinite(a)):
            bad = np.argwhere(~np.isfinite(a))[0]
            raise ValueError(f"action{tuple(bad.tolist()) if self.n > 1 else (int(bad[1]),)} = "
                             f"{a[tuple(bad)]}: expected finite numbers in [-1, 1]")
        a = np.clip(a, -1.0, 1.0)
        return a, self.lo + (a + 1.0) * 0.5 * (self.hi - self.lo)

    def terms(self, a: np.ndarray):
        """The observations (n, 18) float32, rewards, terminated, truncated, crashed and out-of-bounds
        flags of all n vehicles as they stand, for the (clipped) actions `a` (n, k) they flew: envs.py's
        docstring's formulas, computed in C++ in one pass (numpy's dozen passes over the arrays
        cost about as much as stepping the vehicles)."""
        b = self.batch
        if self.tracking:
            ref = b.reference
            p_ref, v_ref = ref["p"], ref["v"]
        else:
            p_ref, v_ref = self.target, None
        hover = np.broadcast_to(self.hover_action, (self.n, self.action_size))
        obs, reward, terminated, crashed, out = b._b.env_terms(p_ref, v_ref, a, hover, self.observation_space.high,
                                                               self.weights, self.limits)
        truncated = self.steps >= self.max_episode_steps
        return obs, reward, terminated, truncated, crashed, out

    def observe(self) -> np.ndarray:
        """The observations (n, 18) float32 of all n vehicles as they stand."""
        return self.terms(np.broadcast_to(self.hover_action, (self.n, self.action_size)))[0]
