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
from typing import Any, Dict, Optional

import numpy as np

from ._episodes import ACTION_SIZE, HOVER_SCENARIO, OBS_SIZE, TRACKING_SCENARIO, _Episodes  # noqa: F401
from .action_levels import ACTION_LEVELS, ACTION_RANGES  # noqa: F401  (envs.ACTION_LEVELS, envs.ACTION_RANGES)
from .batch import Batch
from .spaces import Box
from .starts import RECOVER_START  # noqa: F401  (envs.RECOVER_START)

__all__ = ["Box", "HoverEnv", "TrackingEnv", "VectorHoverEnv", "VectorTrackingEnv"]

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
        e = self._e
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
