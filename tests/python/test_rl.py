"""Starting vehicles anywhere (Batch.reset(states=), the envs' random_start=) and the adapters for
reinforcement-learning libraries (quadcosim.rl: Stable-Baselines3's VecEnv contract, gymnasium
registration). Run by tests/python/run_pytest.sh (CTest python.pytest)."""

import importlib.util
import math

import numpy as np
import pytest

import quadcosim
from quadcosim.envs import HoverEnv, VectorHoverEnv
from quadcosim.rl import ENV_IDS, SB3VecEnv
from quadcosim.starts import RECOVER_START

G = 9.81


def hover_at(p, yaw_rad=0.0):
    return {"name": "hover_at", "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
            "initial": {"position_m": list(p), "yaw_rad": yaw_rad, "hover": True},
            "controller": {"mode": "attitude", "z_des": float(p[2])}}


def fly_hover_speeds(batch, steps):
    omega = np.repeat(batch.vehicle_params["hover_omega_rad_s"][:, None], 4, axis=1)
    for _ in range(steps):
        batch.step(omega_cmd=omega)


def roll_pitch_yaw(q):
    """ZYX Euler angles of (n, 4) quaternions w, x, y, z (an independent formula, not quadcosim's)."""
    w, x, y, z = q.T
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.stack([roll, pitch, yaw], axis=1)


# --- Batch.reset(states=) ----------------------------------------------------------------------------


def test_reset_states_equals_a_scenario_starting_there():
    # Started at (0.3, -0.2, 2.4) with yaw 0.5 by reset(states=) or by the scenario's initial: section,
    # the same numbers bit for bit while both fly the hover speeds.
    p, yaw = [0.3, -0.2, 2.4], 0.5
    q = [math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]
    a = quadcosim.Batch(hover_at([0, 0, 2]), 2, seeds=0, plant_only=True)
    b = quadcosim.Batch(hover_at(p, yaw), 1, seeds=0, plant_only=True)
    np.testing.assert_allclose(b.q[0], q, atol=1e-15)
    a.reset([1], states={"p": [p], "q": b.q})  # the scenario's own quaternion, to the last bit
    np.testing.assert_array_equal(a.p[1], p)
    np.testing.assert_array_equal(a.p[0], [0, 0, 2])  # the other vehicle keeps the scenario's start
    fly_hover_speeds(a, 25)
    fly_hover_speeds(b, 25)
    for k in ("p", "v", "q", "w", "omega"):
        np.testing.assert_array_equal(getattr(a, k)[1], getattr(b, k)[0], err_msg=k)


def test_reset_states_flies_the_physics_from_there():
    # Hover thrust m g tilted by 30 deg of roll: world acceleration (0, -g sin 30, g (cos 30 - 1)) (the body z
    # axis rolled about x points to -y); and a start moving at 1 m/s along x keeps moving (drag is small).
    b = quadcosim.Batch(hover_at([0, 0, 2]), 2, seeds=0, plant_only=True)
    roll = math.radians(30)
    b.reset(states={"q": [[math.cos(roll / 2), math.sin(roll / 2), 0, 0], [1, 0, 0, 0]],
                    "v": [[0, 0, 0], [1.0, 0, 0]]})
    np.testing.assert_array_equal(b.v[1], [1.0, 0, 0])
    fly_hover_speeds(b, 5)  # 0.1 s
    t = 0.1
    assert b.p[0, 1] == pytest.approx(-0.5 * G * math.sin(roll) * t * t, rel=0.05)
    assert b.p[0, 2] - 2 == pytest.approx(0.5 * G * (math.cos(roll) - 1) * t * t, rel=0.05)
    assert b.p[1, 0] == pytest.approx(1.0 * t, rel=0.02)


def test_reset_states_normalises_q_and_refuses_bad_input():
    b = quadcosim.Batch(hover_at([0, 0, 2]), 2, seeds=0, plant_only=True)
    b.reset(states={"q": [[2, 0, 0, 0], [0, 0, 0, 3]]})
    np.testing.assert_allclose(b.q, [[1, 0, 0, 0], [0, 0, 0, 1]], atol=1e-15)
    before = b.state
    for states, words in (({"q": [[0, 0, 0, 0], [1, 0, 0, 0]]}, "norm 0"), ({"p": [[0, 0, 1]]}, "shape"),
                          ({"v": [[0, 0, np.nan], [0, 0, 0]]}, "finite"), ({"omega": [[1, 1, 1, 1]] * 2}, "unknown"),
                          ([[0] * 13] * 2, "dict")):
        with pytest.raises(ValueError, match=words):
            b.reset(states=states)
    for k, v in b.state.items():
        np.testing.assert_array_equal(v, before[k], err_msg=k)  # nothing was reset


# --- random_start ----------------------------------------------------------------------------------


def test_random_start_within_bounds_and_spread():
    env = VectorHoverEnv(400, scenario=hover_at([0, 0, 2]), random_start=RECOVER_START)
    obs, _ = env.reset(seed=7)
    b = env.batch
    off = b.p - [0, 0, 2]
    np.testing.assert_array_equal(obs[:, 0:3], off.astype(np.float32))  # the target stays the scenario's
    assert np.all(np.abs(off) <= 1.0) and np.all(np.abs(off).max(axis=0) > 0.95)
    rpy = roll_pitch_yaw(b.q)
    assert np.all(np.abs(rpy) <= math.radians(30) + 1e-9)
    assert np.all(np.abs(rpy).max(axis=0) > math.radians(28))
    assert np.all(np.abs(b.v) <= 0.2) and np.all(np.abs(b.w) <= 0.2) and np.abs(b.w).max() > 0.18
    # Uniform: about half of each axis' offsets within +-0.5 m (400 draws: 4 sigma is +-0.1).
    assert np.all(np.abs(np.mean(np.abs(off) < 0.5, axis=0) - 0.5) < 0.1)
    np.testing.assert_array_equal(b.omega, np.repeat(b.vehicle_params["hover_omega_rad_s"][:, None], 4, 1))


def test_random_start_is_deterministic_per_seed():
    kw = dict(scenario=hover_at([0, 0, 2]), random_start=RECOVER_START)
    a, b = VectorHoverEnv(5, **kw), VectorHoverEnv(5, **kw)
    oa, _ = a.reset(seed=3)
    ob, _ = b.reset(seed=3)
    np.testing.assert_array_equal(oa, ob)
    oc, _ = b.reset(seed=4)
    assert not np.any(np.all(oc == oa, axis=1))
    # Sub-env i of a vector env seeded s starts where a single env seeded s + i does.
    single = HoverEnv(**kw)
    for i in range(5):
        o, _ = single.reset(seed=3 + i)
        np.testing.assert_array_equal(o, oa[i])
    # Without random_start the start is the scenario's, as before.
    o, _ = HoverEnv(scenario=hover_at([0, 0, 2])).reset(seed=3)
    np.testing.assert_array_equal(o[0:6], np.zeros(6, np.float32))


def test_random_start_refuses_bad_widths():
    for bad, words in (({"position": 1.0}, "unknown"), ({"position_m": -1.0}, ">= 0"),
                       ({"attitude_rad": 4.0}, "at most pi"), ({"rate_rad_s": [1, 2]}, "3 numbers")):
        with pytest.raises(ValueError, match=words):
            HoverEnv(random_start=bad)


# --- Stable-Baselines3's VecEnv contract -------------------------------------------------------------


def test_sb3_vec_env_contract():
    n = 4
    venv = SB3VecEnv(n, scenario=hover_at([0, 0, 2]), random_start=RECOVER_START, max_episode_steps=5)
    assert venv.num_envs == n
    assert tuple(venv.observation_space.shape) == (18,) and tuple(venv.action_space.shape) == (4,)
    assert np.all(venv.action_space.low == -1) and np.all(venv.action_space.high == 1)
    assert venv.seed(11) == [11, 12, 13, 14]
    obs = venv.reset()  # obs only, no info
    assert isinstance(obs, np.ndarray) and obs.shape == (n, 18) and obs.dtype == np.float32
    ref, _ = VectorHoverEnv(n, scenario=hover_at([0, 0, 2]), random_start=RECOVER_START).reset(seed=11)
    np.testing.assert_array_equal(obs, ref)
    hover = np.zeros((n, 4))
    for k in range(5):
        venv.step_async(hover)
        obs2, rewards, dones, infos = venv.step_wait()
        assert obs2.shape == (n, 18) and rewards.shape == (n,) and dones.shape == (n,) and dones.dtype == bool
        assert isinstance(infos, list) and len(infos) == n and all(isinstance(i, dict) for i in infos)
        if k < 4:
            assert not dones.any() and all("terminal_observation" not in i for i in infos)
            last = obs2
    # The time limit ended every episode: the last observation is in the infos, the new episode's first is returned.
    assert dones.all()
    for i in range(n):
        term = infos[i]["terminal_observation"]
        assert term.shape == (18,) and infos[i]["TimeLimit.truncated"] is True
        assert not np.array_equal(term, obs2[i]) and np.max(np.abs(term - last[i])) < 0.5  # one step on
    # A crash is no time limit.
    crash = SB3VecEnv(2, scenario=hover_at([0, 0, 2]), crash_altitude_m=1.999)
    crash.reset()
    for _ in range(20):
        _, _, dones, infos = crash.step(np.full((2, 4), -1.0))
        if dones.any():
            break
    assert dones.all() and all(i["TimeLimit.truncated"] is False and i["crashed"] for i in infos)
    assert venv.get_attr("num_envs") == [n] * n and venv.get_attr("num_envs", [0, 2]) == [n, n]
    assert venv.env_is_wrapped(object) == [False] * n
    assert len(venv.env_method("close")) == n
    with pytest.raises(ValueError, match="shape"):
        venv.step_async(np.zeros((n, 3)))
    with pytest.raises(ValueError, match="same_step"):
        SB3VecEnv(VectorHoverEnv(2))


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is None,
                    reason="stable_baselines3 is not installed: the contract is checked above without it")
def test_sb3_takes_the_vec_env():
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecEnv
    venv = SB3VecEnv(4, random_start=RECOVER_START)
    assert isinstance(venv, VecEnv)
    PPO("MlpPolicy", venv, n_steps=32, batch_size=64, n_epochs=1, seed=0, device="cpu").learn(128)


@pytest.mark.skipif(importlib.util.find_spec("gymnasium") is None,
                    reason="gymnasium is not installed: registration is skipped by design without it")
def test_gymnasium_registration():
    import gymnasium
    from gymnasium.utils.env_checker import check_env
    for env_id in ENV_IDS:
        assert env_id in gymnasium.registry
    env = gymnasium.make("quadcosim/Hover-v0", random_start=RECOVER_START)
    check_env(env.unwrapped)
    obs, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs)
    venv = gymnasium.make_vec("quadcosim/VectorHover-v0", num_envs=3, vectorization_mode="vector_entry_point")
    obs, _ = venv.reset(seed=0)
    assert obs.shape == (3, 18)


def test_without_gymnasium_nothing_is_registered():
    if importlib.util.find_spec("gymnasium") is not None:
        pytest.skip("gymnasium is installed: test_gymnasium_registration checks the registration")
    from quadcosim import rl
    assert rl.register_envs() is False
    assert type(SB3VecEnv(1).observation_space).__name__ == "Box"


def test_rotation_matrices_of_the_attitudes():
    env = VectorHoverEnv(50, scenario=hover_at([0, 0, 2]), random_start=RECOVER_START)
    obs, _ = env.reset(seed=1)
    q = env.batch.q
    w, x, y, z = q.T  # the textbook formula, in numpy
    expected = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                         2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    np.testing.assert_allclose(env.batch.R, expected, atol=1e-15)
    np.testing.assert_allclose(obs[:, 6:15], expected, atol=1e-7)


def test_reset_states_on_whole_simulations():
    # Message faults make every vehicle a whole Simulation (not the lean plant): its start is set there too,
    # bit for bit as a scenario starting there, with its controller flying.
    faulty = dict(hover_at([0, 0, 2]), message_faults={"topics": {"Imu": {"delay_ticks": 1}}})
    a = quadcosim.Batch(faulty, 1, seeds=5)
    assert not a._b.lean_vehicles()
    a.reset(states={"p": [[0.2, 0.1, 1.8]]})
    b = quadcosim.Batch(dict(faulty, initial={"position_m": [0.2, 0.1, 1.8], "hover": True}), 1, seeds=5)
    for _ in range(25):
        a.step()
        b.step()
    for k in ("p", "v", "q", "w", "omega"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)
    assert abs(a.p[0, 2] - 1.8) > 1e-3  # its controller (z_des 2 m) flies it


def test_random_start_of_tracking_envs_is_around_the_scenarios_start():
    from quadcosim.envs import VectorTrackingEnv
    env = VectorTrackingEnv(50, random_start={"position_m": [0.5, 0.5, 0.2]})
    env.reset(seed=2)
    off = env.batch.p - [1.0, 0.0, 1.0]  # TRACKING_SCENARIO starts at (1, 0, 1)
    assert np.all(np.abs(off) <= [0.5, 0.5, 0.2]) and np.all(np.abs(off).max(axis=0) > [0.4, 0.4, 0.15])
    np.testing.assert_array_equal(env.batch.q, np.tile([1.0, 0, 0, 0], (50, 1)))  # attitude_rad left out: 0
