"""The environments for reinforcement-learning libraries, neither of which quadcosim depends on.

    from quadcosim.rl import SB3VecEnv
    venv = SB3VecEnv(16, random_start=quadcosim.starts.RECOVER_START)   # Stable-Baselines3's VecEnv
    model = stable_baselines3.PPO("MlpPolicy", venv, seed=0).learn(200_000)

    import gymnasium, quadcosim.rl                                      # registers quadcosim/Hover-v0, ...
    env = gymnasium.make("quadcosim/Hover-v0", random_start=quadcosim.starts.RECOVER_START)

SB3VecEnv: n sub-envs of one VectorHoverEnv (or VectorTrackingEnv) under Stable-Baselines3's VecEnv
contract: reset() -> obs (n, 18); step_async(actions) then step_wait() -> (obs, rewards, dones,
infos) with dones = terminated or truncated, the ended sub-envs reset at once (the returned row is
the new episode's first observation) and their last observation in infos[i]["terminal_observation"],
infos[i]["TimeLimit.truncated"] True when the time limit (not a crash or leaving the box) ended it;
seed(s) seeds sub-env i with s + i at the next reset(); num_envs, observation_space and action_space
of one sub-env. When stable_baselines3 is importable the class derives from its VecEnv (so its
algorithms take it as it is) and the spaces are gymnasium.spaces.Box; otherwise from object, with
quadcosim.spaces.Box spaces of the same bounds.

register_envs(): registers with gymnasium, when it is importable, quadcosim/Hover-v0,
quadcosim/Tracking-v0 (single envs, wrapped as gymnasium.Env with gymnasium.spaces.Box spaces) and
quadcosim/VectorHover-v0 (gymnasium.make_vec(..., vectorization_mode="vector_entry_point") makes a
VectorHoverEnv: one Batch for all sub-envs). Importing this module calls it; without gymnasium it
does nothing. Every keyword (scenario, random_start, reward_weights, action, ...) goes through to the
env's constructor.
"""

import importlib.util
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from . import envs as _envs

__all__ = ["SB3VecEnv", "register_envs", "ENV_IDS"]

ENV_IDS = ("quadcosim/Hover-v0", "quadcosim/Tracking-v0", "quadcosim/VectorHover-v0")


def _importable(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


if _importable("stable_baselines3"):
    from stable_baselines3.common.vec_env import VecEnv as _VecEnvBase
else:
    _VecEnvBase = object


def _library_box(box: Any) -> Any:
    """gymnasium.spaces.Box with box's bounds and dtype when gymnasium is importable, else box itself."""
    if not _importable("gymnasium"):
        return box
    import gymnasium
    return gymnasium.spaces.Box(low=box.low, high=box.high, shape=box.shape, dtype=box.dtype)


class SB3VecEnv(_VecEnvBase):
    """Stable-Baselines3's VecEnv over n sub-envs of one Batch (see the module's docstring).

    SB3VecEnv(num_envs, kind="hover", **env_kwargs): a new VectorHoverEnv (kind "tracking": a
    VectorTrackingEnv) with env_kwargs (random_start=..., reward_weights=..., action=..., ...);
    SB3VecEnv(vector_env): one already made (its autoreset_mode must be "same_step").
    """

    def __init__(self, num_envs: Any, kind: str = "hover", **env_kwargs: Any):
        if isinstance(num_envs, _envs._VectorEnv):
            if env_kwargs or kind != "hover":
                raise ValueError("SB3VecEnv: give a vector env or num_envs with its arguments, not both")
            venv = num_envs
            if venv.autoreset_mode != "same_step":
                raise ValueError("SB3VecEnv: the vector env must reset an ended sub-env in the step that ends it "
                                 "(autoreset_mode='same_step'), as Stable-Baselines3 expects")
        else:
            cls = {"hover": _envs.VectorHoverEnv, "tracking": _envs.VectorTrackingEnv}.get(kind)
            if cls is None:
                raise ValueError(f"SB3VecEnv: kind = {kind!r}: expected 'hover' or 'tracking'")
            if env_kwargs.get("autoreset_mode", "same_step") != "same_step":
                raise ValueError("SB3VecEnv: autoreset_mode must be 'same_step' (Stable-Baselines3's contract)")
            env_kwargs["autoreset_mode"] = "same_step"
            venv = cls(num_envs, **env_kwargs)
        self.venv = venv
        obs_space = _library_box(venv.single_observation_space)
        act_space = _library_box(venv.single_action_space)
        if _VecEnvBase is object:
            self.num_envs, self.observation_space, self.action_space = venv.num_envs, obs_space, act_space
            self.render_mode = None
            self._seeds: List[Optional[int]] = [None] * venv.num_envs
            self._options: List[Dict[str, Any]] = [{} for _ in range(venv.num_envs)]
        else:
            super().__init__(venv.num_envs, obs_space, act_space)
        self.metadata = {"render_modes": [], "autoreset_mode": "same_step"}
        self._actions: Optional[np.ndarray] = None
        self.reset_infos: List[Dict[str, Any]] = [{} for _ in range(venv.num_envs)]

    # --- the VecEnv contract --------------------------------------------------------------------------

    def seed(self, seed: Optional[int] = None) -> Sequence[Optional[int]]:
        """Sub-env i gets seed + i at the next reset() (None: fresh entropy). Returns the seeds."""
        if seed is None:
            self._seeds = [None] * self.num_envs
        else:
            self._seeds = [int(seed) + i for i in range(self.num_envs)]
        return list(self._seeds)

    def set_options(self, options: Optional[Any] = None) -> None:
        """Options for the next reset(); the vector envs take none but reset_mask, so only None or {}."""
        if options and any(options if isinstance(options, list) else [options]):
            raise ValueError(f"SB3VecEnv.set_options: the quadcosim vector envs take no reset options, got {options!r}")

    def reset(self) -> np.ndarray:
        """Resets every sub-env (with the seeds of seed(), then forgotten). Returns obs (n, 18)."""
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        obs, _ = self.venv.reset(seed=seeds)
        self._seeds = [None] * self.num_envs
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        a = np.asarray(actions)
        if a.shape != (self.num_envs,) + tuple(self.action_space.shape):
            raise ValueError(f"SB3VecEnv.step_async: actions: expected shape "
                             f"{(self.num_envs,) + tuple(self.action_space.shape)}, got {a.shape}")
        self._actions = a

    def step_wait(self):
        """(obs (n, 18) float32, rewards (n,) float32, dones (n,) bool, infos: list of n dicts)."""
        if self._actions is None:
            raise RuntimeError("SB3VecEnv.step_wait: call step_async(actions) first")
        actions, self._actions = self._actions, None
        obs, rewards, terminated, truncated, info = self.venv.step(actions)
        dones = terminated | truncated
        infos: List[Dict[str, Any]] = []
        for i in range(self.num_envs):
            d = {"t": float(info["t"][i]), "crashed": bool(info["crashed"][i]),
                 "out_of_bounds": bool(info["out_of_bounds"][i])}
            if dones[i]:
                d["terminal_observation"] = info["final_obs"][i].copy()
                d["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            infos.append(d)
        return obs, rewards.astype(np.float32), dones, infos

    def step(self, actions: np.ndarray):
        self.step_async(actions)
        return self.step_wait()

    def close(self) -> None:
        self.venv.close()

    def _indices(self, indices: Any) -> List[int]:
        if indices is None:
            return list(range(self.num_envs))
        if isinstance(indices, int):
            return [indices]
        return [int(i) for i in indices]

    def get_attr(self, attr_name: str, indices: Any = None) -> List[Any]:
        """The attribute of the vector env (the sub-envs share it), once per index."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        """Sets an attribute of the vector env: only for all sub-envs at once (they share one object)."""
        if self._indices(indices) != list(range(self.num_envs)):
            raise ValueError("SB3VecEnv.set_attr: the sub-envs share one vector env: set attributes of all of them")
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> List[Any]:
        """Calls the vector env's method once and gives its result once per index."""
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        return [result for _ in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class: Any, indices: Any = None) -> List[bool]:
        """No sub-env is wrapped (Stable-Baselines3 asks whether a Monitor is there: wrap with VecMonitor)."""
        return [False for _ in self._indices(indices)]

    def get_images(self) -> Sequence[Optional[np.ndarray]]:
        return [None for _ in range(self.num_envs)]

    def render(self, mode: Optional[str] = None) -> None:
        return None

    @property
    def unwrapped(self) -> "SB3VecEnv":
        return self


def _gymnasium_env(kind: str, **kwargs: Any):
    """A quadcosim single env as a gymnasium.Env (gymnasium's wrappers require one) with gymnasium spaces."""
    import gymnasium

    cls = {"hover": _envs.HoverEnv, "tracking": _envs.TrackingEnv}[kind]

    class QuadcosimEnv(gymnasium.Env):
        metadata = {"render_modes": []}

        def __init__(self, **kw: Any):
            self.env = cls(**kw)
            self.observation_space = _library_box(self.env.observation_space)
            self.action_space = _library_box(self.env.action_space)

        def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
            super().reset(seed=seed)
            return self.env.reset(seed=seed, options=options)

        def step(self, action: Any):
            return self.env.step(action)

        @property
        def batch(self):
            return self.env.batch

    QuadcosimEnv.__name__ = QuadcosimEnv.__qualname__ = cls.__name__
    return QuadcosimEnv(**kwargs)


def make_hover(**kwargs: Any):
    """gymnasium's entry point of quadcosim/Hover-v0."""
    return _gymnasium_env("hover", **kwargs)


def make_tracking(**kwargs: Any):
    """gymnasium's entry point of quadcosim/Tracking-v0."""
    return _gymnasium_env("tracking", **kwargs)


def make_vector_hover(num_envs: int, **kwargs: Any) -> _envs.VectorHoverEnv:
    """gymnasium's vector entry point of quadcosim/VectorHover-v0: a VectorHoverEnv with gymnasium spaces."""
    venv = _envs.VectorHoverEnv(num_envs, **kwargs)
    for name in ("single_observation_space", "single_action_space", "observation_space", "action_space"):
        setattr(venv, name, _library_box(getattr(venv, name)))
    return venv


def register_envs() -> bool:
    """Registers ENV_IDS with gymnasium when it is importable (each once). True when registered. Also
    gymnasium's plugin hook (pyproject.toml's entry point "gymnasium.envs"), so an installed quadcosim's
    ids exist as soon as gymnasium is imported."""
    if not _importable("gymnasium"):
        return False
    from gymnasium.envs.registration import register, registry  # loaded before gymnasium calls its plugins
    # No max_episode_steps: the envs truncate their episodes themselves (max_episode_steps=, 500 and 1000
    # by default); gymnasium.make(..., max_episode_steps=k) would add a TimeLimit.
    entries = {"quadcosim/Hover-v0": dict(entry_point="quadcosim.rl:make_hover"),
               "quadcosim/Tracking-v0": dict(entry_point="quadcosim.rl:make_tracking"),
               "quadcosim/VectorHover-v0": dict(vector_entry_point="quadcosim.rl:make_vector_hover")}
    for env_id, kw in entries.items():
        if env_id not in registry:
            register(id=env_id, **kw)
    return True


register_envs()
