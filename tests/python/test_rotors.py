"""Vehicles with more than four rotors from Python: Batch, Simulation and the envs size their rotor arrays
and actions by the rotor count (a hexarotor: 6), and a wrong width is refused by name."""

import numpy as np
import pytest

import quadcosim
from quadcosim.envs import HoverEnv, VectorHoverEnv


def hex_hover(vehicle=None):
    """The firefly preset (six rotors, hex_x) in trimmed hover at 2 m."""
    return {
        "name": "hex_hover",
        "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
        "vehicle": vehicle or {"preset": "firefly"},
        "initial": {"position_m": [0.0, 0.0, 2.0], "hover": True},
        "controller": {"type": "se3", "mode": "position", "z_des": 2.0},
    }


def test_a_hex_batch_has_six_rotor_columns_and_steps():
    b = quadcosim.Batch(hex_hover(), 3, threads=1)
    assert b.omega.shape == (3, 6)
    assert b.command.shape == (3, 6)
    vp = b.vehicle_params
    assert np.all(vp["rotor_count"] == 6)
    # Hover speed for six rotors: sqrt(m g / (6 k_t)).
    hover = np.sqrt(vp["mass_kg"] * vp["gravity_m_s2"] / (6 * vp["kt_N_per_rad2_s2"]))
    np.testing.assert_allclose(vp["hover_omega_rad_s"], hover, rtol=1e-12)
    np.testing.assert_allclose(b.omega, np.repeat(hover[:, None], 6, axis=1), rtol=1e-12)
    b.step(periods=25)  # the se3 controllers fly
    assert b.command.shape == (3, 6) and np.all(np.isfinite(b.command))
    np.testing.assert_allclose(b.p, [[0.0, 0.0, 2.0]] * 3, atol=1e-6)
    # Rotor speeds bypassing the controllers: one per rotor.
    b.step(omega_cmd=np.repeat(hover[:, None], 6, axis=1))
    np.testing.assert_allclose(b.command, np.repeat(hover[:, None], 6, axis=1), rtol=1e-12)
    with pytest.raises(ValueError, match=r"expected an array of shape \(3, 6\) \(6 rotor speeds"):
        b.step(omega_cmd=np.full((3, 4), 500.0))


def test_a_hex_batch_refuses_rotor_thrusts_and_another_rotor_count():
    with pytest.raises(ValueError, match="rotor_thrusts is a four-rotor level"):
        quadcosim.Batch(hex_hover(), 2, threads=1, action="rotor_thrusts")
    with pytest.raises(quadcosim.ConfigError, match="every vehicle of a batch has the scenario's 6"):
        quadcosim.Batch(hex_hover(), 2, threads=1, vehicles=[{}, {"layout": "octo_x"}])


def test_a_hex_simulation_takes_six_speeds():
    sim = quadcosim.Simulation(quadcosim.load_scenario(hex_hover()))
    sim.step()
    assert sim.state["omega"].shape == (6,)
    assert sim.command.shape == (6,)
    sim.step(omega_cmd=np.full(6, 560.0))
    np.testing.assert_allclose(sim.command, np.full(6, 560.0))
    with pytest.raises(ValueError, match="expected 6 rotor speeds"):
        sim.step(omega_cmd=np.full(4, 560.0))


def test_hex_envs_act_with_six_rotor_speeds():
    env = HoverEnv(scenario=hex_hover())
    assert env.action_space.shape == (6,)
    obs, _ = env.reset(seed=1)
    assert obs.shape == (18,)
    obs, reward, terminated, truncated, info = env.step(env.hover_action[0])
    assert np.isfinite(reward) and not terminated
    assert info["omega_cmd"].shape == (6,)
    with pytest.raises(ValueError, match=r"expected shape \(6,\)"):
        env.step(np.zeros(4))
    venv = VectorHoverEnv(4, scenario=hex_hover())
    assert venv.action_space.shape == (4, 6)
    venv.reset(seed=3)
    obs, rewards, terminated, truncated, _ = venv.step(venv.hover_action)
    assert obs.shape == (4, 18) and np.all(np.isfinite(rewards))
    # Above rotor speeds the action stays four values.
    assert HoverEnv(scenario=hex_hover(), action="ctbr").action_space.shape == (4,)
