"""Command levels from Python: Batch(action=...) and the envs' action levels (docs/python.md, "Action
levels"). Run by tests/python/run_pytest.sh (CTest python.pytest)."""

import math
import os
import pathlib

import numpy as np
import pytest

import quadcosim
from quadcosim.envs import ACTION_LEVELS, HoverEnv, VectorHoverEnv

SOURCE = pathlib.Path(os.environ.get("QUADCOSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))

HOVER = {
    "name": "levels_hover",
    "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
    "initial": {"position_m": [0.0, 0.0, 5.0], "hover": True},
    "controller": {"mode": "attitude", "z_des": 5.0},
}
WEIGHT_N = 1.96 * 9.81  # the paper's vehicle


@pytest.fixture(autouse=True)
def _in_source_dir(monkeypatch):
    monkeypatch.chdir(SOURCE)


def ctbr_sequence(steps, n):
    """Varying ctbr setpoints: thrust around m g, small body-rate steps, one row per vehicle."""
    t = np.arange(steps)[:, None] * 0.02
    rows = np.arange(n)[None, :]
    return np.stack([WEIGHT_N * (1 + 0.03 * np.sin(t + rows)), 0.2 * np.cos(2 * t + rows),
                     np.where(t < 0.4, 0.1, -0.1) + 0 * rows, 0.05 * np.sin(t) + 0 * rows], axis=2)


def test_ctbr_batch_without_a_bus_equals_whole_simulations_bit_for_bit():
    """Lean vehicles (the plant core stepped directly) and whole Simulations (the command published on
    the in-process bus, taken in by the plant node) fly the same ctbr setpoints to the same bits.
    Faults on /clock change nothing a Batch's vehicle computes; they only make it a whole Simulation."""
    faulty = dict(HOVER, message_faults={"topics": {"clock": {"drop_probability": 0.5}}})
    lean = quadcosim.Batch(HOVER, 3, plant_only=True, action="ctbr")
    full = quadcosim.Batch(faulty, 3, action="ctbr")
    assert lean.plant_only and not full.plant_only and lean.action == full.action == "ctbr"
    for command in ctbr_sequence(60, 3):
        lean.step(command)
        full.step(command)
        for name in ("p", "v", "q", "w", "omega", "command", "t"):
            a, b = getattr(lean, name), getattr(full, name)
            assert a.tobytes() == b.tobytes(), name
    assert np.all(np.abs(lean.w) > 0)  # the rates were flown


def test_ctbr_hover_holds_altitude_and_zero_rates():
    b = quadcosim.Batch(HOVER, 2, plant_only=True, action="ctbr")
    b.step(np.tile([WEIGHT_N, 0.0, 0.0, 0.0], (2, 1)), periods=250)  # 10 s
    assert np.allclose(b.p[:, 2], 5.0, atol=1e-6)
    assert np.all(np.abs(b.w) < 1e-9)


def test_velocity_level_reaches_the_command_with_its_time_constant():
    """Vertical: v_z(t) = v (1 - exp(-K_v t)) at the ticks, K_v = 1.5 rad/s on the paper's vehicle at 100 Hz."""
    b = quadcosim.Batch(HOVER, 1, plant_only=True, action="velocity")
    for k in range(1, 51):
        b.step(np.array([[0.0, 0.0, 1.0, 0.0]]))
        assert abs(b.v[0, 2] - (1 - math.exp(-1.5 * b.t[0]))) < 1e-9


def test_rotor_thrusts_are_square_roots_of_thrust_over_kt():
    b = quadcosim.Batch(HOVER, 1, plant_only=True, action="rotor_thrusts")
    T = np.array([[4.0, 5.0, 6.0, 4.5]])
    b.step(T)
    assert np.array_equal(b.command, np.sqrt(T / 2.06e-7))


def test_bad_commands_and_levels_are_refused_naming_what_is_wrong():
    with pytest.raises(ValueError, match=r"unknown command level 'ctrb'; the levels are rotor_speeds, rotor_thrusts, "
                                         r"ctbr, ctatt, cttm, velocity, acceleration.*did you mean 'ctbr'"):
        quadcosim.Batch(HOVER, 1, plant_only=True, action="ctrb")
    b = quadcosim.Batch(HOVER, 2, plant_only=True, action="ctbr")
    with pytest.raises(ValueError, match=r"ctbr commands: expected an array of shape \(2, 4\) \(thrust \[N\], "
                                         r"p \[rad/s\], q \[rad/s\], r \[rad/s\] per vehicle\), got shape \(2, 3\)"):
        b.step(np.zeros((2, 3)))
    bad = np.tile([WEIGHT_N, 0.0, 0.0, 0.0], (2, 1))
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"ctbr commands\[1, 2\] \(q \[rad/s\]\) = nan: commands must be finite"):
        b.step(bad)
    with pytest.raises(ValueError, match=r"this batch's action is 'ctbr'"):
        b.step(omega_cmd=np.zeros((2, 4)))
    assert np.all(b.t == 0)  # nothing was stepped


@pytest.mark.parametrize("level", ACTION_LEVELS)
def test_the_hover_action_of_every_level_hovers(level):
    """The action that commands hover (a_hover of the reward) holds the vehicle at every level."""
    env = HoverEnv(scenario=HOVER, action=level)
    env.reset(seed=0)
    a = env._e.hover_action[0].astype(np.float32)
    assert env.action_space.contains(a)
    for _ in range(50):
        obs, reward, terminated, truncated, info = env.step(a)
    assert not terminated
    assert np.all(np.abs(obs[:3]) < 1e-3), level  # position error [m]
    assert info["command"].shape == (4,) and info["omega_cmd"].shape == (4,)


def test_env_ctbr_actions_map_onto_their_documented_ranges():
    env = VectorHoverEnv(2, scenario=HOVER, action="ctbr")
    env.reset(seed=0)
    e = env._e
    t_max = 4 * 2.06e-7 * 12000.0**2
    assert np.allclose(e.lo[0], [0.0, -3.0, -3.0, -3.0]) and np.allclose(e.hi[0], [t_max, 3.0, 3.0, 3.0])
    assert np.allclose(e.hover_action[0], [2 * WEIGHT_N / t_max - 1, 0.0, 0.0, 0.0])
    _, command = e.command(np.array([[1.0, -1.0, 0.5, 2.0], [-1.0, 0.0, 0.0, -0.5]]))
    assert np.allclose(command, [[t_max, -3.0, 1.5, 3.0], [0.0, 0.0, 0.0, -1.5]])  # clipped to [-1, 1]
    with pytest.raises(ValueError, match=r"action = 'ctrb': expected one of rotor_speeds"):
        HoverEnv(action="ctrb")


def test_the_scenarios_inner_loops_set_the_gains_and_unstable_ones_are_refused():
    """inner_loops: {rate_bandwidth: 20}: a roll-rate step settles as 1 - exp(-20 t) at the ticks."""
    tuned = dict(HOVER, inner_loops={"rate_bandwidth": 20.0})
    b = quadcosim.Batch(tuned, 1, plant_only=True, action="ctbr")
    for _ in range(10):
        b.step(np.array([[WEIGHT_N, 0.3, 0.0, 0.0]]))
        assert abs(b.w[0, 0] - 0.3 * (1 - math.exp(-20.0 * b.t[0]))) < 1e-12
    with pytest.raises(quadcosim.ConfigError, match=r"inner_loops.*inner.attitude_bandwidth 300 rad/s is unstable"):
        quadcosim.Batch(dict(HOVER, inner_loops={"attitude_bandwidth": 300.0}), 1, plant_only=True, action="ctbr")
    with pytest.raises(quadcosim.ConfigError, match=r"rate_bandwith"):
        quadcosim.Batch(dict(HOVER, inner_loops={"rate_bandwith": 20.0}), 1, plant_only=True)


def test_simulation_step_at_a_level_equals_a_batch_vehicle_bit_for_bit():
    """Simulation.step(command=, level=) bypasses the controller like omega_cmd= and hands the plant a
    level command: the same bits as a Batch vehicle (the plant core stepped without a bus) flying it."""
    sim = quadcosim.Simulation(HOVER)
    lean = quadcosim.Batch(HOVER, 1, plant_only=True, action="ctbr")
    for command in ctbr_sequence(40, 1):
        sim.step(command=command[0], level="ctbr")
        lean.step(command)
        state = sim.state
        for name in ("p", "v", "q", "w", "omega"):
            assert state[name].tobytes() == getattr(lean, name)[0].tobytes(), name
    assert np.abs(sim.state["w"]).max() > 0.01  # the rates were flown


def test_simulation_step_at_a_level_refuses_what_is_wrong():
    sim = quadcosim.Simulation(HOVER)
    with pytest.raises(ValueError, match="unknown command level 'ctrb'.*did you mean 'ctbr'"):
        sim.step(command=np.zeros(4), level="ctrb")
    with pytest.raises(ValueError, match=r"ctbr: value 3 \(q \[rad/s\]\) is nan"):
        sim.step(command=np.array([WEIGHT_N, 0.0, math.nan, 0.0]), level="ctbr")
    with pytest.raises(ValueError, match=r"command: expected 4 values \(velocity: .*got an array of shape \(3,\)"):
        sim.step(command=np.zeros(3), level="velocity")
    with pytest.raises(ValueError, match="not both"):
        sim.step(np.zeros(4), command=np.zeros(4), level="ctbr")
    with pytest.raises(ValueError, match="needs command="):
        sim.step(level="ctbr")
    assert sim.t == 0.0  # nothing refused was flown
