"""Gymnasium-style environments over quadcosim.Batch, with no dependency on gymnasium.

    env = quadcosim.envs.HoverEnv()
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

HoverEnv holds a position; TrackingEnv follows a trajectory (the scenario's `trajectory:` or one
given). VectorHoverEnv(n) and VectorTrackingEnv(n) run n of them on one Batch with Gymnasium's
vector-env contract and auto-reset. The API follows Gymnasium 1.x (reset(seed, options) -> (obs,
info); step(action) -> (obs, reward, terminated, truncated, info); observation_space, action_space,
np_random); quadcosim.rl registers them with gymnasium when it is installed and adapts the vector
envs to Stable-Baselines3. See docs/python.md,
"Gymnasium-style environments".

Spaces (float32):
  action (4,) (at rotor_speeds (N,), one per rotor of the vehicle: 6 for a hexarotor): normalised
  commands in [-1, 1] (values outside are clipped) at the env's action level
      (action=, default "rotor_speeds"), each mapped linearly from [-1, 1] onto its range [lo, hi]:
      c_i = lo_i + (a_i + 1) / 2 * (hi_i - lo_i); the controller is bypassed. The ranges (ACTION_RANGES,
      the vehicle's k_t, k_m, arm length L, omega_min, omega_max):
        rotor_speeds   omega_i in [omega_min, omega_max] [rad/s]
        rotor_thrusts  T_i in [k_t omega_min^2, k_t omega_max^2] [N]
        ctbr           thrust in [0, N k_t omega_max^2] [N]; p, q, r in [-3, 3] rad/s (body FLU)
        ctatt          thrust as ctbr; roll, pitch in [-0.5, 0.5] rad; yaw in [-pi, pi] rad
        cttm           thrust as ctbr; torque x, y in [-L k_t omega_max^2, +] [N m]; z in
                       [-2 k_m omega_max^2, +] [N m]
        velocity       v_x, v_y, v_z in [-2, 2] m/s (world ENU); yaw in [-pi, pi] rad
        acceleration   a_x, a_y, a_z in [-4, 4] m/s^2 (world, gravity excluded); yaw in [-pi, pi] rad
      Above rotor speeds the plant's inner loops fly the command every plant tick (docs/controllers.md).
  observation (18,): [0:3] position error p - p_ref [m, world]; [3:6] velocity error v - v_ref
      [m/s, world] (v_ref = 0 for hovering); [6:15] attitude as the rotation matrix body -> world, row
      by row (R[0,0], R[0,1], ..., R[2,2]); [15:18] body rates [rad/s]. Clipped to the space's bounds
      (+-max_position_error_m, +-max_speed_m_s, +-1, +-max_rate_rad_s).
Reward per step: 1 - (w_p |e_p|^2 + w_v |e_v|^2 + w_w |w|^2 + w_a |a - a_hover|^2), a_hover the action
  that commands hover (rotor speeds sqrt(m g / (4 k_t)); rotor thrusts m g / 4; thrust m g with zero
  rates, angles or torques; zero velocity or acceleration); minus termination_penalty on the step
  that terminates. Weights default to w_p 1, w_v 0.1, w_w 0.01, w_a 0.01.
Terminated: a crash (z below crash_altitude_m, or tilted more than max_tilt_rad) or leaving the box
  |e_p| <= max_position_error_m on every axis. Truncated: after max_episode_steps steps.
Start: the scenario's initial state, or with random_start={"position_m": 1.0, "attitude_rad": 0.52,
  "velocity_m_s": 0.2, "rate_rad_s": 0.2} (starts.RECOVER_START; half-widths of uniform draws per axis,
  docs in quadcosim/starts.py) anywhere near the target: hover-and-recover. Step period: the scenario's
  control period (HOVER_SCENARIO: 20 ms, 50 Hz). Stable-Baselines3 and gymnasium: quadcosim.rl.
"""

import math
import numbers
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._quadcosim import ConfigError
from .action_levels import ACTION_LEVELS, ACTION_RANGES, action_ranges as _action_ranges
from .batch import Batch
from .spaces import Box
from .starts import RECOVER_START, check_start, draw_start  # noqa: F401  (RECOVER_START: envs.RECOVER_START)

__all__ = ["Box", "HoverEnv", "TrackingEnv", "VectorHoverEnv", "VectorTrackingEnv"]


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
        flags of all n vehicles as they stand, for the (clipped) actions `a` (n, 4) they flew: the
        module docstring's formulas, computed in C++ in one pass (numpy's dozen passes over the arrays
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


def _env_kwargs(kind: str, scenario, trajectory, target, max_episode_steps, max_position_error_m, crash_altitude_m,
                max_tilt_rad, max_speed_m_s, max_rate_rad_s, reward_weights, termination_penalty, randomize,
                random_start=None, action="rotor_speeds"):
    return dict(tracking=kind == "tracking", scenario=scenario, trajectory=trajectory, target=target,
                max_episode_steps=max_episode_steps, max_position_error_m=max_position_error_m,
                crash_altitude_m=crash_altitude_m, max_tilt_rad=max_tilt_rad, max_speed_m_s=max_speed_m_s,
                max_rate_rad_s=max_rate_rad_s, reward_weights=reward_weights,
                termination_penalty=termination_penalty, randomize=randomize, random_start=random_start,
                action=action)


class _BatchEnv:
    """What _Env and _VectorEnv share: the Batch they step and Gymnasium's unwrapped, close and
    context-manager contract."""

    @property
    def unwrapped(self):
        return self

    @property
    def batch(self) -> Batch:
        """The Batch the env steps (its vehicles' state, sensors, vehicle parameters)."""
        return self._e.batch

    @property
    def hover_action(self) -> np.ndarray:
        """(n, k) the normalised action that commands hover at the env's action level, one row per
        (sub-)env (the reward's a_hover)."""
        return self._e.hover_action

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()


class _Env(_BatchEnv):
    """One vehicle (a Batch of 1): Gymnasium's Env contract."""

    metadata: Dict[str, Any] = {"render_modes": []}
    render_mode = None
    spec = None

    def __init__(self, kind: str, **kw: Any):
        self._e = _Episodes(1, threads=1, **kw)
        self.observation_space = self._e.observation_space
        self.action_space = self._e.action_space
        self.np_random = np.random.default_rng()
        self._target_option = None

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
        """Starts an episode: the scenario's initial state, a fresh noise seed and (with randomize) new
        vehicle parameters, both drawn from np_random (reseeded by seed: the same seed, the same episode).
        options: {"target": [x, y, z]} the position to hold (HoverEnv; default the scenario's initial
        position). Returns (obs, info)."""
        if seed is not None:
            self.np_random = np.random.default_rng(seed)
        options = options or {}
        unknown = set(options) - {"target"}
        if unknown:
            raise ValueError(f"reset: unknown options {sorted(unknown)}; expected 'target'")
        target = None
        if "target" in options:
            if self._e.tracking:
                raise ValueError("reset: options['target'] is for HoverEnv; TrackingEnv follows its trajectory")
            target = np.broadcast_to(np.asarray(options["target"], dtype=float), (3,))[None]
        self._e.reset(np.array([0]), [self.np_random], target)
        obs = self._e.observe()
        return obs[0], self._info(np.zeros(1, bool), np.zeros(1, bool))

    def step(self, action: Any):
        """Flies one control period with the command the action maps to. Returns (obs, reward,
        terminated, truncated, info); info: t [s], crashed, out_of_bounds, command (at the env's action
        level), omega_cmd [rad/s] (the rotor speeds latched in the period's last tick)."""
        e = self._e
        if e.ended[0]:
            raise RuntimeError("step: the episode has ended (or never began): call reset() first")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (e.action_size,):
            raise ValueError(f"step: action: expected shape ({e.action_size},), got {a.shape}")
        a, command = e.command(a[None])
        e.batch.step(command)
        e.steps += 1
        obs, reward, terminated, truncated, crashed, out = e.terms(a)
        e.ended[0] = bool(terminated[0] or truncated[0])
        info = self._info(crashed, out)
        info["command"] = command[0]
        info["omega_cmd"] = command[0] if e.action == "rotor_speeds" else e.batch.command[0]
        return obs[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), info

    def _info(self, crashed: np.ndarray, out: np.ndarray) -> Dict[str, Any]:
        return {"t": float(self._e.batch.t[0]), "crashed": bool(crashed[0]), "out_of_bounds": bool(out[0])}

    def render(self):
        return None


class HoverEnv(_Env):
    """Hold a position with the four rotor speeds (see the module's docstring for spaces, reward, termination).

    scenario: a Scenario, file or dict (default HOVER_SCENARIO: a trimmed hover at (0, 0, 1) m, no noise);
    target: the position to hold [m] (default: the scenario's initial position; reset(options=
    {"target": ...}) for one episode); max_episode_steps: truncation (default 500, 10 s at 50 Hz);
    max_position_error_m: the box around the target (2 m); crash_altitude_m (0.05 m) and max_tilt_rad
    (pi/2): what counts as a crash; max_speed_m_s (10), max_rate_rad_s (20): observation bounds;
    reward_weights: {"position", "velocity", "rate", "action"}; termination_penalty (10);
    action: the command level of the actions ("rotor_speeds", default; "rotor_thrusts", "ctbr", "ctatt",
    "cttm", "velocity", "acceleration": ranges in the module's docstring);
    randomize: domain randomisation on every reset, {vehicle key: (low, high)} drawn uniformly, e.g.
    {"mass_kg": (0.4, 0.55), "motor.tau_up_s": (0.02, 0.05)} (vector keys take arrays of 3);
    random_start: a random start on every reset around the target, {"position_m", "attitude_rad",
    "velocity_m_s", "rate_rad_s"}: half-widths of uniform draws per axis (starts.RECOVER_START: 1 m,
    30 deg, 0.2 m/s, 0.2 rad/s; see quadcosim/starts.py); None: the scenario's initial state.
    """

    def __init__(self, scenario: Any = None, target: Any = None, max_episode_steps: int = 500,
                 max_position_error_m: float = 2.0, crash_altitude_m: float = 0.05, max_tilt_rad: float = math.pi / 2,
                 max_speed_m_s: float = 10.0, max_rate_rad_s: float = 20.0,
                 reward_weights: Optional[Dict[str, float]] = None, termination_penalty: float = 10.0,
                 randomize: Optional[Dict[str, Any]] = None, random_start: Optional[Dict[str, Any]] = None,
                 action: str = "rotor_speeds"):
        super().__init__("hover", **_env_kwargs("hover", scenario, None, target, max_episode_steps,
                                                max_position_error_m, crash_altitude_m, max_tilt_rad, max_speed_m_s,
                                                max_rate_rad_s, reward_weights, termination_penalty, randomize,
                                                random_start, action))


class TrackingEnv(_Env):
    """Follow a trajectory with the four rotor speeds: the observation's errors are to the trajectory's
    position and velocity at the vehicle's time.

    scenario: one with a `trajectory:` section (default TRACKING_SCENARIO: a 1 m circle at 1 m, see
    scenarios/tracking/ for others); trajectory: the keys of a `trajectory:` section replacing the
    scenario's (e.g. {"kind": "figure8", ...}, docs/scenarios.md). Other arguments as HoverEnv's
    (max_episode_steps defaults to 1000: 20 s at 50 Hz).
    """

    def __init__(self, scenario: Any = None, trajectory: Optional[Dict[str, Any]] = None,
                 max_episode_steps: int = 1000, max_position_error_m: float = 2.0, crash_altitude_m: float = 0.05,
                 max_tilt_rad: float = math.pi / 2, max_speed_m_s: float = 10.0, max_rate_rad_s: float = 20.0,
                 reward_weights: Optional[Dict[str, float]] = None, termination_penalty: float = 10.0,
                 randomize: Optional[Dict[str, Any]] = None, random_start: Optional[Dict[str, Any]] = None,
                 action: str = "rotor_speeds"):
        super().__init__("tracking", **_env_kwargs("tracking", scenario, trajectory, None, max_episode_steps,
                                                   max_position_error_m, crash_altitude_m, max_tilt_rad, max_speed_m_s,
                                                   max_rate_rad_s, reward_weights, termination_penalty, randomize,
                                                   random_start, action))


class _VectorEnv(_BatchEnv):
    """n sub-envs on one Batch: Gymnasium's VectorEnv contract, auto-reset included.

    autoreset_mode "next_step" (Gymnasium 1.x's default, AutoresetMode.NEXT_STEP): the step after a
    sub-env's episode ended resets it instead of stepping it (its action is ignored) and returns its
    first observation with reward 0, terminated and truncated False. "same_step"
    (AutoresetMode.SAME_STEP): the ending step resets it at once and returns the new episode's first
    observation; the last one is in info["final_obs"] (rows of finished sub-envs; NaN elsewhere) with the
    mask info["_final_obs"].
    """

    def __init__(self, kind: str, num_envs: int, autoreset_mode: str = "next_step", threads: Optional[int] = None,
                 **kw: Any):
        if autoreset_mode not in ("next_step", "same_step"):
            raise ValueError(f"autoreset_mode = {autoreset_mode!r}: expected 'next_step' or 'same_step'")
        if isinstance(num_envs, bool) or not isinstance(num_envs, numbers.Integral) or num_envs < 1:
            raise ValueError(f"num_envs = {num_envs!r}: expected an integer >= 1")
        self.num_envs = int(num_envs)
        self.autoreset_mode = autoreset_mode
        self.metadata = {"render_modes": [], "autoreset_mode": autoreset_mode}
        self.render_mode = None
        self._e = _Episodes(self.num_envs, threads=threads, **kw)
        self.single_observation_space = self._e.observation_space
        self.single_action_space = self._e.action_space
        o, a = self.single_observation_space, self.single_action_space
        self.observation_space = Box(np.broadcast_to(o.low, (self.num_envs,) + o.shape),
                                     np.broadcast_to(o.high, (self.num_envs,) + o.shape), dtype=o.dtype)
        self.action_space = Box(-1.0, 1.0, (self.num_envs, self._e.action_size), dtype=a.dtype)
        self._rngs = [np.random.default_rng() for _ in range(self.num_envs)]
        self._autoreset = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed: Any = None, options: Optional[Dict[str, Any]] = None):
        """Resets every sub-env (or those of options["reset_mask"]). seed: an int s seeds sub-env i with
        s + i (as Gymnasium's vector envs; so sub-env i repeats HoverEnv().reset(seed=s + i)), or a list of
        n seeds (None entries: fresh entropy). Returns (obs (n, 18), info)."""
        n = self.num_envs
        if seed is not None:
            seeds = [seed + i for i in range(n)] if isinstance(seed, numbers.Integral) else list(seed)
            if len(seeds) != n:
                raise ValueError(f"reset: {len(seeds)} seeds for {n} sub-envs")
            self._rngs = [np.random.default_rng(s) for s in seeds]
        options = options or {}
        unknown = set(options) - {"reset_mask"}
        if unknown:
            raise ValueError(f"reset: unknown options {sorted(unknown)}; expected 'reset_mask'")
        mask = np.ones(n, dtype=bool) if "reset_mask" not in options else np.asarray(options["reset_mask"], dtype=bool)
        if mask.shape != (n,):
            raise ValueError(f"reset: options['reset_mask']: expected {n} booleans, got shape {mask.shape}")
        self._e.reset(np.flatnonzero(mask), self._rngs, None)
        self._autoreset[mask] = False
        obs = self._e.observe()
        return obs, self._info(np.zeros(n, bool), np.zeros(n, bool))

    def step(self, actions: Any):
        """Steps every sub-env with its action ((n, 4) in [-1, 1]). Returns (obs (n, 18) float32,
        rewards (n,) float64, terminated (n,) bool, truncated (n,) bool, info: dict of (n,) arrays t,
        crashed, out_of_bounds)."""
        e, n = self._e, self.num_envs
        a, command = e.command(actions)
        pending = self._autoreset.copy()
        if np.any(e.ended & ~pending):
            raise RuntimeError("step: call reset() first")
        e.batch.step(command)
        e.steps += 1
        if self.autoreset_mode == "next_step" and np.any(pending):
            e.reset(np.flatnonzero(pending), self._rngs, None)  # the step just made for them is discarded
        obs, reward, terminated, truncated, crashed, out = e.terms(a)
        if self.autoreset_mode == "next_step":
            reward[pending] = 0.0
            terminated[pending] = truncated[pending] = crashed[pending] = out[pending] = False
        done = terminated | truncated
        info = self._info(crashed, out)
        if self.autoreset_mode == "same_step":
            final = np.full_like(obs, np.nan)
            final[done] = obs[done]
            info["final_obs"], info["_final_obs"] = final, done.copy()
            if np.any(done):
                e.reset(np.flatnonzero(done), self._rngs, None)
                obs = e.observe()
            self._autoreset[:] = False
        else:
            e.ended[done] = True
            self._autoreset = done.copy()
        return obs, reward, terminated, truncated, info

    def _info(self, crashed: np.ndarray, out: np.ndarray) -> Dict[str, np.ndarray]:
        return {"t": self._e.batch.t, "crashed": crashed, "out_of_bounds": out}


class VectorHoverEnv(_VectorEnv):
    """num_envs HoverEnvs on one Batch (arguments as HoverEnv's, plus autoreset_mode and threads)."""

    def __init__(self, num_envs: int, scenario: Any = None, target: Any = None, max_episode_steps: int = 500,
                 max_position_error_m: float = 2.0, crash_altitude_m: float = 0.05, max_tilt_rad: float = math.pi / 2,
                 max_speed_m_s: float = 10.0, max_rate_rad_s: float = 20.0,
                 reward_weights: Optional[Dict[str, float]] = None, termination_penalty: float = 10.0,
                 randomize: Optional[Dict[str, Any]] = None, random_start: Optional[Dict[str, Any]] = None,
                 autoreset_mode: str = "next_step", threads: Optional[int] = None,
                 action: str = "rotor_speeds"):
        super().__init__("hover", num_envs, autoreset_mode, threads,
                         **_env_kwargs("hover", scenario, None, target, max_episode_steps, max_position_error_m,
                                       crash_altitude_m, max_tilt_rad, max_speed_m_s, max_rate_rad_s, reward_weights,
                                       termination_penalty, randomize, random_start, action))


class VectorTrackingEnv(_VectorEnv):
    """num_envs TrackingEnvs on one Batch (arguments as TrackingEnv's, plus autoreset_mode and threads)."""

    def __init__(self, num_envs: int, scenario: Any = None, trajectory: Optional[Dict[str, Any]] = None,
                 max_episode_steps: int = 1000, max_position_error_m: float = 2.0, crash_altitude_m: float = 0.05,
                 max_tilt_rad: float = math.pi / 2, max_speed_m_s: float = 10.0, max_rate_rad_s: float = 20.0,
                 reward_weights: Optional[Dict[str, float]] = None, termination_penalty: float = 10.0,
                 randomize: Optional[Dict[str, Any]] = None, random_start: Optional[Dict[str, Any]] = None,
                 autoreset_mode: str = "next_step", threads: Optional[int] = None,
                 action: str = "rotor_speeds"):
        super().__init__("tracking", num_envs, autoreset_mode, threads,
                         **_env_kwargs("tracking", scenario, trajectory, None, max_episode_steps,
                                       max_position_error_m, crash_altitude_m, max_tilt_rad, max_speed_m_s,
                                       max_rate_rad_s, reward_weights, termination_penalty, randomize, random_start,
                                       action))
