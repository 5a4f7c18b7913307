"""The envs' observation, reward and termination (computed in C++, quadcosim.Batch.env_terms) against
the formulas of quadcosim/envs.py's docstring written out in numpy here. Run by
tests/python/run_pytest.sh (CTest python.pytest)."""

import math

import numpy as np
import pytest

from quadcosim.envs import RECOVER_START, VectorHoverEnv, VectorTrackingEnv

WEIGHTS = {"position": 1.0, "velocity": 0.1, "rate": 0.01, "action": 0.01}


def rotation_matrices(q):
    """R_WB of unit quaternions (w, x, y, z), row by row: the textbook formula."""
    w, x, y, z = q.T
    return np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)


def expected(env, a, p_ref, v_ref, max_tilt_rad=math.pi / 2, crash_altitude_m=0.05, max_error_m=2.0,
             penalty=10.0):
    b = env.batch
    e_p, e_v, w = b.p - p_ref, b.v - v_ref, b.w
    rot = rotation_matrices(b.q)
    high = env.observation_space.high.astype(np.float64)
    obs = np.clip(np.concatenate([e_p, e_v, rot, w], axis=1), -high, high).astype(np.float32)
    cost = (WEIGHTS["position"] * (e_p ** 2).sum(1) + WEIGHTS["velocity"] * (e_v ** 2).sum(1)
            + WEIGHTS["rate"] * (w ** 2).sum(1) + WEIGHTS["action"] * ((a - env.hover_action) ** 2).sum(1))
    crashed = (b.p[:, 2] < crash_altitude_m) | (rot[:, 8] < math.cos(max_tilt_rad))
    out = np.any(np.abs(e_p) > max_error_m, axis=1)
    return obs, 1.0 - cost - penalty * (crashed | out), crashed, out


def test_hover_env_terms_are_the_documented_formulas():
    env = VectorHoverEnv(32, random_start=RECOVER_START, max_episode_steps=10**6, autoreset_mode="same_step",
                         target=[0.0, 0.0, 1.0])
    rng = np.random.default_rng(7)
    actions = rng.uniform(-1.3, 1.3, (60, 32, 4))  # some outside [-1, 1]: clipped before the reward
    ended = 0

    def p_ref():
        return np.tile([0.0, 0.0, 1.0], (32, 1))

    env.reset(seed=4)
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        if np.any(terminated):
            ended += int(terminated.sum())
            continue  # same_step: those sub-envs were reset after being judged; checked in the other test
        want_obs, want_reward, want_crashed, want_out = expected(env, np.clip(a, -1, 1), p_ref(), 0.0)
        assert obs.dtype == np.float32 and obs.shape == (32, 18)
        assert np.array_equal(obs, want_obs)
        np.testing.assert_allclose(reward, want_reward, rtol=0, atol=1e-12)
        assert not np.any(want_crashed | want_out)
    assert ended > 0  # random actions ended some episodes


def test_crash_and_termination_are_judged_on_the_state_reached():
    env = VectorHoverEnv(4, max_episode_steps=10**6, target=[0.0, 0.0, 1.0])
    env.reset(seed=1)
    cut = np.repeat(env.hover_action[:1], 4, axis=0)
    cut[0] = -1.0  # vehicle 0: every motor at its lowest speed: it falls
    cut[1, 0] = 1.0  # vehicle 1: one rotor at full speed: it flips
    first = {}
    for step in range(200):
        pending = env._autoreset.copy()  # sub-envs this step resets (next_step mode): reward 0
        obs, reward, terminated, truncated, info = env.step(cut)
        want_obs, want_reward, want_crashed, want_out = expected(env, cut, np.tile([0.0, 0.0, 1.0], (4, 1)), 0.0)
        assert np.array_equal(obs, want_obs)
        live = ~pending
        np.testing.assert_allclose(reward[live], want_reward[live], rtol=0, atol=1e-12)
        assert np.array_equal(info["crashed"][live], want_crashed[live])
        assert np.array_equal(terminated[live], (want_crashed | want_out)[live])
        assert np.all(reward[pending] == 0.0) and not np.any(terminated[pending])
        for i in np.flatnonzero(terminated):
            first.setdefault(int(i), (step, reward[i], info["crashed"][i]))
        if 0 in first and 1 in first:
            break
    assert first[0][2] and first[0][1] < -9  # crashed, the penalty paid
    assert first[1][2] and first[1][1] < -9
    assert 2 not in first and 3 not in first and reward[2] > 0.99 and reward[3] > 0.99  # hovering


def test_tracking_env_terms_use_the_reference():
    env = VectorTrackingEnv(8, max_episode_steps=10**6)
    env.reset(seed=2)
    rng = np.random.default_rng(3)
    for _ in range(40):
        a = np.clip(np.repeat(env.hover_action[:1], 8, axis=0) + rng.normal(0, 0.02, (8, 4)), -1, 1)
        live = ~env._autoreset  # sub-envs this step resets (next_step mode) report reward 0
        obs, reward, terminated, truncated, info = env.step(a)
        ref = env.batch.reference
        want_obs, want_reward, want_crashed, want_out = expected(env, a, ref["p"], ref["v"])
        assert np.array_equal(obs, want_obs)
        np.testing.assert_allclose(reward[live], want_reward[live], rtol=0, atol=1e-12)
        assert np.array_equal(terminated[live], (want_crashed | want_out)[live])
    assert np.abs(ref["v"]).max() > 0  # the reference moved


def test_wrong_shapes_are_refused_by_name():
    env = VectorHoverEnv(3)
    env.reset(seed=0)
    b = env.batch._b
    ok = dict(p_ref=np.zeros((3, 3)), v_ref=None, action=np.zeros((3, 4)), hover_action=np.zeros((3, 4)),
              obs_bound=np.ones(18), weights=WEIGHTS,
              limits={"crash_altitude_m": 0.0, "cos_max_tilt": 0.0, "max_position_error_m": 1.0,
                      "termination_penalty": 0.0})
    b.env_terms(**ok)
    for name, bad in (("p_ref", np.zeros((2, 3))), ("action", np.zeros((3, 3))), ("obs_bound", np.ones(17)),
                      ("v_ref", np.zeros(3))):
        with pytest.raises(ValueError, match=f"env_terms: {name}: expected shape"):
            b.env_terms(**dict(ok, **{name: bad}))


def test_a_hexarotor_envs_reward_counts_its_six_actions():
    """At rotor speeds a hexarotor's action has six entries, and all six enter the action cost."""
    scenario = {"name": "hex_terms", "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
                "vehicle": {"preset": "firefly"}, "initial": {"position_m": [0.0, 0.0, 1.0], "hover": True},
                "controller": {"mode": "attitude", "z_des": 1.0}}
    env = VectorHoverEnv(5, scenario=scenario, max_episode_steps=10**6, target=[0.0, 0.0, 1.0])
    assert env.action_space.shape == (5, 6)
    env.reset(seed=0)
    rng = np.random.default_rng(11)
    for _ in range(10):
        a = np.clip(env.hover_action + rng.normal(0, 0.01, (5, 6)), -1, 1)
        live = ~env._autoreset
        obs, reward, terminated, truncated, info = env.step(a)
        want_obs, want_reward, _, _ = expected(env, a, np.tile([0.0, 0.0, 1.0], (5, 1)), 0.0)
        assert np.array_equal(obs, want_obs)
        np.testing.assert_allclose(reward[live], want_reward[live], rtol=0, atol=1e-12)
