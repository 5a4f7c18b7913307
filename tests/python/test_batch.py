"""quadcosim.Batch against single quadcosim.Simulations, and the Gymnasium-style environments'
contract (run by tests/python/run_pytest.sh, CTest python.pytest)."""

import copy
import math
import os
import pathlib

import numpy as np
import pytest

import quadcosim
from quadcosim import _quadcosim
from quadcosim.envs import Box, HoverEnv, TrackingEnv, VectorHoverEnv, VectorTrackingEnv

SOURCE = pathlib.Path(os.environ.get("QUADCOSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
NOISY_FILE = "scenarios/realism/roll_step_noisy_imu.yaml"  # seeded IMU noise: seeds matter
STATE = ("p", "v", "q", "w", "omega")


@pytest.fixture(autouse=True)
def _in_source_dir(monkeypatch):
    monkeypatch.chdir(SOURCE)


def noisy_hover(vehicle=None):
    """A trimmed hover at 2 m with a noisy IMU and position sensor (the controller flies on them)."""
    d = {
        "name": "noisy_hover",
        "seed": 11,
        "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": 10},
        "sensors": {"imu": {"gyro_noise_density_rad_s_sqrt_hz": 0.0003, "accel_noise_density_m_s2_sqrt_hz": 0.004,
                            "orientation_sigma_rad": 0.002}},
        "initial": {"position_m": [0.0, 0.0, 2.0], "hover": True},
        "controller": {"mode": "attitude", "z_des": 2.0},
    }
    if vehicle:
        d["vehicle"] = copy.deepcopy(vehicle)
    return d


EXTRA_SENSORS = ("magnetometer", "barometer", "gnss")


def snapshot_single(sim):
    s = sim.sensors
    snap = {**{k: sim.state[k] for k in STATE}, "command": sim.command, "t": np.array(sim.t),
            "imu.a": s["imu"]["a"], "imu.w": s["imu"]["w"], "pose.p": s["pose"]["p"], "velocity.v": s["velocity"]["v"]}
    for sensor in EXTRA_SENSORS:  # the extra sensors a scenario configures (a GNSS fix as 1.0 / 0.0 in a Batch)
        for k, v in s.get(sensor, {}).items():
            snap[f"{sensor}.{k}"] = np.asarray(v, dtype=float)
    return snap


def snapshot_row(batch, i):
    s = batch.sensors
    snap = {**{k: batch.state[k][i] for k in STATE}, "command": batch.command[i], "t": np.array(batch.t[i]),
            "imu.a": s["imu"]["a"][i], "imu.w": s["imu"]["w"][i], "pose.p": s["pose"]["p"][i],
            "velocity.v": s["velocity"]["v"][i]}
    for sensor in EXTRA_SENSORS:
        for k, v in s.get(sensor, {}).items():
            snap[f"{sensor}.{k}"] = v[i]
    return snap


def assert_same(a, b, what):
    assert sorted(a) == sorted(b), f"{what}: {sorted(a)} != {sorted(b)}"
    for k in a:
        assert np.array_equal(a[k], b[k], equal_nan=True), f"{what}: {k}: {a[k]} != {b[k]}"


# --- a batch flies exactly what single simulations fly --------------------------------------------------

VEHICLES = [None, {"mass_kg": 0.5}, {"mass_kg": 0.45, "motor": {"model": "first_order", "tau_up_s": 0.03,
                                                                  "tau_down_s": 0.04}},
            {"Ixx_kg_m2": 0.005, "aero": {"linear_drag_N_s_m": [0.1, 0.1, 0.2]}}]


def test_each_vehicle_equals_its_single_simulation_bit_for_bit():
    """Different seeds, vehicle parameters and setpoints; controllers flying, then rotor commands."""
    n = len(VEHICLES)
    seeds = [3, 17, 17, 2**40 + 5]
    zs = [2.5, 1.0, 3.0, 2.0]
    batch = quadcosim.Batch(noisy_hover(), n, seeds=seeds, vehicles=VEHICLES, threads=2)
    singles = [quadcosim.Simulation(quadcosim.load_scenario(noisy_hover(v)), seed=s) for v, s in zip(VEHICLES, seeds)]
    batch.set_setpoints(z=zs)
    for sim, z in zip(singles, zs):
        sim.set_setpoint(z=z)
    rng = np.random.default_rng(0)
    for k in range(120):
        if k >= 80:  # rotor commands from outside for the last steps
            cmd = 4500.0 + rng.uniform(-200, 200, size=(n, 4))
            batch.step(omega_cmd=cmd)
            for i, sim in enumerate(singles):
                sim.step(omega_cmd=cmd[i])
        else:
            batch.step()
            for sim in singles:
                sim.step()
        if k % 20 == 0 or k == 119:
            for i, sim in enumerate(singles):
                assert_same(snapshot_single(sim), snapshot_row(batch, i), f"vehicle {i} step {k}")
    assert np.array_equal(batch.seeds, np.array(seeds, dtype=np.uint64))
    # The vehicles really differ (else the test would prove little): seeds and masses change the numbers.
    assert not np.array_equal(batch.p[1], batch.p[2])
    assert not np.array_equal(batch.sensors["imu"]["a"][0], batch.sensors["imu"]["a"][3])


def test_a_file_scenario_with_default_seeds():
    """seeds=None: vehicle i flies the scenario's seed + i."""
    sc = quadcosim.load_scenario(NOISY_FILE)
    batch = quadcosim.Batch(sc, 3, threads=1)
    for _ in range(50):
        batch.step()
    for i in range(3):
        sim = quadcosim.Simulation(sc, seed=sc.seed + i)
        for _ in range(50):
            sim.step()
        assert_same(snapshot_single(sim), snapshot_row(batch, i), f"vehicle {i}")


def test_dict_of_arrays_equals_list_of_dicts():
    masses = np.array([0.4, 0.47, 0.52])
    drag = np.array([[0.0, 0.0, 0.1], [0.1, 0.1, 0.1], [0.2, 0.0, 0.0]])
    a = quadcosim.Batch(noisy_hover(), 3, vehicles={"mass_kg": masses, "aero.linear_drag_N_s_m": drag}, threads=1)
    b = quadcosim.Batch(noisy_hover(), 3, threads=1, vehicles=[
        {"mass_kg": float(m), "aero": {"linear_drag_N_s_m": d.tolist()}} for m, d in zip(masses, drag)])
    np.testing.assert_array_equal(a.vehicle_params["mass_kg"], masses)
    np.testing.assert_array_equal(a.vehicle_params["aero.linear_drag_N_s_m.z"], drag[:, 2])
    for _ in range(30):
        a.step()
        b.step()
    for k in STATE:
        assert np.array_equal(getattr(a, k), getattr(b, k)), k


def test_hover_speed_of_every_vehicle():
    masses = [0.3, 0.468, 0.9]
    batch = quadcosim.Batch(noisy_hover(), 3, vehicles={"mass_kg": masses}, threads=1)
    vp = batch.vehicle_params
    expected = np.sqrt(np.array(masses) * vp["gravity_m_s2"] / (4 * vp["kt_N_per_rad2_s2"]))
    np.testing.assert_allclose(vp["hover_omega_rad_s"], expected, rtol=1e-15)
    # Trimmed starts: the initial rotor speeds are each vehicle's hover speed.
    np.testing.assert_allclose(batch.omega, np.repeat(expected[:, None], 4, 1), rtol=1e-12)


def test_thread_count_changes_no_number():
    runs = []
    for threads in (1, 2, 3):
        b = quadcosim.Batch(noisy_hover(), 37, vehicles={"mass_kg": np.linspace(0.4, 0.55, 37)}, threads=threads)
        b.set_setpoints(z=np.linspace(1.0, 3.0, 37))
        for k in range(60):
            b.step()
            if k == 30:
                b.reset([3, 20], seeds=[99, 100])
        b.step(omega_cmd=np.full((37, 4), 4700.0), periods=3)
        runs.append({**b.state, **{"s." + k: v for k, v in b.sensors["imu"].items()}, "t": b.t})
    for other in runs[1:]:
        for k in runs[0]:
            assert np.array_equal(runs[0][k], other[k], equal_nan=True), k


def test_periods_equal_repeated_steps():
    a = quadcosim.Batch(noisy_hover(), 5, threads=2)
    b = quadcosim.Batch(noisy_hover(), 5, threads=1)
    a.step(periods=25)
    for _ in range(25):
        b.step()
    cmd = np.full((5, 4), 4600.0)
    a.step(omega_cmd=cmd, periods=4)
    for _ in range(4):
        b.step(omega_cmd=cmd)
    for k in STATE + ("t",):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert np.array_equal(a.tick, np.full(5, 29 * a.ticks_per_step))


def test_reset_repeats_and_per_vehicle_reset():
    batch = quadcosim.Batch(noisy_hover(), 4, seeds=[1, 2, 3, 4], threads=2)
    for _ in range(40):
        batch.step()
    first = batch.state
    batch.reset()
    np.testing.assert_array_equal(batch.t, np.zeros(4))
    for _ in range(40):
        batch.step()
    for k in STATE:
        assert np.array_equal(first[k], batch.state[k]), k
    # Vehicle 2 restarts with seed 50; the others go on.
    batch.reset([2], seeds=[50])
    assert list(batch.seeds) == [1, 2, 50, 4]
    for _ in range(10):
        batch.step()
    np.testing.assert_allclose(batch.t, [1.0, 1.0, 0.2, 1.0])
    sim2 = quadcosim.Simulation(quadcosim.load_scenario(noisy_hover()), seed=50)
    sim0 = quadcosim.Simulation(quadcosim.load_scenario(noisy_hover()), seed=1)
    for _ in range(10):
        sim2.step()
    for _ in range(50):
        sim0.step()
    assert_same(snapshot_single(sim2), snapshot_row(batch, 2), "vehicle 2 after its reset")
    assert_same(snapshot_single(sim0), snapshot_row(batch, 0), "vehicle 0, not reset")
    # New vehicle parameters on reset (domain randomisation between episodes).
    batch.reset([1], vehicles=[{"mass_kg": 0.6}])
    assert batch.vehicle_params["mass_kg"][1] == 0.6
    assert batch.vehicle_params["mass_kg"][0] != 0.6


def test_sensors_are_nan_before_the_first_step():
    batch = quadcosim.Batch(noisy_hover(), 2, threads=1)
    assert np.all(np.isnan(batch.sensors["imu"]["a"]))
    batch.step()
    assert np.all(np.isfinite(batch.sensors["imu"]["a"]))
    batch.reset([1])
    assert np.all(np.isfinite(batch.sensors["imu"]["a"][0])) and np.all(np.isnan(batch.sensors["imu"]["a"][1]))


# --- bad inputs: clear errors, state untouched --------------------------------------------------------


def stepped_batch():
    b = quadcosim.Batch(noisy_hover(), 3, seeds=[5, 6, 7], threads=2)
    for _ in range(10):
        b.step()
    return b


def assert_untouched(b):
    """b (stepped_batch(), possibly after refused calls) goes on exactly as a batch nobody bothered."""
    ref = stepped_batch()
    for k in STATE + ("t",):
        assert np.array_equal(getattr(b, k), getattr(ref, k)), k
    for k, v in ref.setpoints.items():
        assert np.array_equal(v, b.setpoints[k]), k
    b.step()
    ref.step()
    for k in STATE:
        assert np.array_equal(getattr(b, k), getattr(ref, k)), k


@pytest.mark.parametrize("cmd, match", [
    (np.full((3, 3), 4000.0), r"shape \(3, 4\).*got shape \(3, 3\).*nothing was stepped"),
    (np.full((2, 4), 4000.0), r"got shape \(2, 4\)"),
    (np.full(4, 4000.0), r"got shape \(4,\)"),
])
def test_wrong_command_shapes_are_refused(cmd, match):
    b = stepped_batch()
    with pytest.raises(ValueError, match=match):
        b.step(omega_cmd=cmd)
    assert_untouched(b)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_commands_that_are_not_finite_are_refused(bad):
    b = stepped_batch()
    cmd = np.full((3, 4), 4500.0)
    cmd[2, 1] = bad
    with pytest.raises(ValueError, match=r"omega_cmd\[2, 1\] = .*finite; nothing was stepped"):
        b.step(omega_cmd=cmd)
    assert_untouched(b)


def test_bad_vehicle_keys_name_vehicle_key_and_value():
    with pytest.raises(quadcosim.ConfigError, match=r"vehicle 1: <dict>: vehicle\.mas_kg: unknown key"):
        quadcosim.Batch(noisy_hover(), 3, vehicles=[None, {"mas_kg": 0.5}, None])
    with pytest.raises(quadcosim.ConfigError, match=r"vehicle 2: <dict>: vehicle\.mass_kg: got '-0\.5'.*expected"):
        quadcosim.Batch(noisy_hover(), 3, vehicles={"mass_kg": [0.5, 0.4, -0.5]})
    with pytest.raises(quadcosim.ConfigError, match=r"vehicle 0: .*motor\.tau_up_s.*nan"):
        quadcosim.Batch(noisy_hover(), 2, vehicles={"motor.tau_up_s": [math.nan, 0.02]})
    with pytest.raises(quadcosim.ConfigError, match=r"expected 3 values \(one per vehicle\), got an array of shape \(2,\)"):
        quadcosim.Batch(noisy_hover(), 3, vehicles={"mass_kg": [0.5, 0.4]})
    with pytest.raises(quadcosim.ConfigError, match=r"2 dicts for 3 vehicles"):
        quadcosim.Batch(noisy_hover(), 3, vehicles=[{}, {}])


def test_bad_resets_change_nothing():
    b = stepped_batch()
    with pytest.raises(quadcosim.ConfigError, match=r"vehicle 1: .*mass_kg"):
        b.reset([0, 1], vehicles=[{"mass_kg": 0.5}, {"mass_kg": 0.0}])
    with pytest.raises(IndexError, match=r"vehicle index 3 out of range"):
        b.reset([0, 3])
    with pytest.raises(ValueError, match=r"seeds"):
        b.reset([0, 1], seeds=[1])
    with pytest.raises(ValueError, match=r"seeds\[0\] = -1"):
        b.reset([0], seeds=[-1])
    assert_untouched(b)


def test_bad_setpoints_change_nothing():
    b = stepped_batch()
    with pytest.raises(ValueError, match=r"vehicle 2: z = 1000000000\.0: z_des must be in .*no setpoint was changed"):
        b.set_setpoints(z=[1.0, 2.0, 1e9], yaw=0.3)
    with pytest.raises(ValueError, match=r"vehicle 1: z = nan"):
        b.set_setpoints(z=[1.0, np.nan, 2.0])
    with pytest.raises(ValueError, match=r"an array of 3 numbers"):
        b.set_setpoints(z=[1.0, 2.0])
    with pytest.raises(TypeError, match=r"unknown setpoint 'altitude'"):
        b.set_setpoints(altitude=1.0)
    with pytest.raises(ValueError, match=r"mode = 'hover'"):
        b.set_setpoints(mode=["attitude", "attitude", "hover"])
    assert_untouched(b)
    b.set_setpoints([1], z=[4.0])
    assert list(b.setpoints["z"]) == [2.0, 4.0, 2.0]


# --- plant_only: the plants alone, the same numbers ------------------------------------------------------

ALL_ARRAYS = STATE + ("command", "t")


def realistic_hover(watchdog_s=0.5):
    """Everything a plant does besides integrating: noisy sensors at their own rates with latency, wind
    and gusts, drag, motor lag, a rotor losing efficiency, RK4 substeps, a command delay, the watchdog."""
    return {
        "name": "realistic_hover",
        "seed": 4,
        "simulation": {"plant_rate_hz": 200, "controller_rate_hz": 50, "substeps": 2, "command_delay_ticks": 5,
                       "watchdog_s": watchdog_s},
        "sensors": {"imu": {"gyro_noise_density_rad_s_sqrt_hz": 0.0003, "accel_noise_density_m_s2_sqrt_hz": 0.004,
                            "gyro_bias_random_walk_rad_s2_sqrt_hz": 0.0001, "orientation_sigma_rad": 0.002,
                            "latency_ticks": 1},
                    "pose": {"position_sigma_m": 0.01, "orientation_sigma_rad": 0.003, "rate_hz": 50,
                             "latency_ticks": 3},
                    "velocity": {"linear_sigma_m_s": 0.02, "rate_hz": 100}},
        "environment": {"wind_m_s": [2, -1, 0], "gusts": {"w20_m_s": 7.7, "altitude_m": 5}},
        "faults": [{"at_s": 0.3, "rotor": 2, "efficiency": 0.7}],
        "vehicle": {"aero": {"linear_drag_N_s_m": [0.25, 0.25, 0.4]},
                    "motor": {"model": "first_order", "tau_up_s": 0.03, "tau_down_s": 0.04}},
        "initial": {"position_m": [0, 0, 5], "hover": True},
        "controller": {"mode": "position", "z_des": 5},
    }


def assert_same_bits(a, b, what):
    """Every array of a and b the same, byte for byte (NaN before the first sample included)."""
    for k in a:
        assert a[k].dtype == b[k].dtype and a[k].shape == b[k].shape and a[k].tobytes() == b[k].tobytes(), \
            f"{what}: {k}: {a[k]} != {b[k]}"


def every_array(batch):
    out = {k: getattr(batch, k) for k in ALL_ARRAYS}
    out["tick"] = batch.tick
    for sensor, fields in batch.sensors.items():
        for k, a in fields.items():
            out[f"{sensor}.{k}"] = a
    return out


def fly_commands(batches, steps, rng, n):
    """Rotor commands around hover, some out of range (clamped by the plant), now and then several
    periods per call; every batch flies the same."""
    for k in range(steps):
        cmd = 4000.0 + rng.uniform(-600, 600, size=(n, 4))
        if k % 7 == 3:
            cmd[k % n, k % 4] = -50.0 if k % 2 else 1e6  # clamped to [0, omega_max]
        periods = 1 + (k % 5 == 0) * 2
        for b in batches:
            b.step(omega_cmd=cmd, periods=periods)
        yield k


@pytest.mark.parametrize("watchdog_s", [0.5, 0.01])  # 0.01 s: 2 ticks, the watchdog stops the motors between commands
def test_plant_only_equals_the_full_vehicles_bit_for_bit(watchdog_s):
    vehicles = [None, {"mass_kg": 0.5}, {"Ixx_kg_m2": 0.005, "motor": {"tau_up_s": 0.02}}]
    seeds = [3, 17, 2**40 + 5]
    n = len(vehicles)
    sc = realistic_hover(watchdog_s)
    full = quadcosim.Batch(sc, n, seeds=seeds, vehicles=vehicles, threads=2)
    lean = quadcosim.Batch(sc, n, seeds=seeds, vehicles=vehicles, threads=2, plant_only=True)
    assert lean.plant_only and not full.plant_only
    assert_same_bits(every_array(full), every_array(lean), "before stepping")
    rng = np.random.default_rng(1)
    omega_max = lean.vehicle_params["motor.omega_max_rad_s"][:, None]
    clamped = 0
    for k in fly_commands([full, lean], 60, rng, n):
        clamped += np.count_nonzero((lean.command == 0.0) | (lean.command == omega_max))
        if k % 10 == 0 or k == 59:
            assert_same_bits(every_array(full), every_array(lean), f"step {k}")
    # The run did what it is meant to exercise (else equality would prove little).
    assert lean.tick[0] > 0.3 / lean.plant_period_s  # past the rotor fault
    assert not np.array_equal(lean.p[0], lean.p[1])
    assert not np.array_equal(lean.sensors["pose"]["p"], lean.p)  # noisy, and late
    if watchdog_s < 0.05:
        assert np.all(lean.command == 0.0)  # the last tick of a period: the watchdog has stopped the motors
    else:
        assert clamped > 0  # commands out of range were latched clamped
    # Reset: back to t = 0 for some, the others fly on; still the same numbers.
    for b in (full, lean):
        b.reset([1], seeds=[99], vehicles=[{"mass_kg": 0.45}])
    assert_same_bits(every_array(full), every_array(lean), "after reset")
    for k in fly_commands([full, lean], 20, rng, n):
        pass
    assert_same_bits(every_array(full), every_array(lean), "after reset and steps")


def test_plant_only_equals_a_single_simulation():
    sc = realistic_hover()
    lean = quadcosim.Batch(sc, 2, seeds=[8, 9], threads=1, plant_only=True)
    sims = [quadcosim.Simulation(quadcosim.load_scenario(sc), seed=s) for s in (8, 9)]
    rng = np.random.default_rng(2)
    for k in range(40):
        cmd = 4000.0 + rng.uniform(-600, 600, size=(2, 4))
        lean.step(omega_cmd=cmd)
        for i, sim in enumerate(sims):
            sim.step(omega_cmd=cmd[i])
    for i, sim in enumerate(sims):
        assert_same(snapshot_single(sim), snapshot_row(lean, i), f"vehicle {i}")


def test_plant_only_refuses_what_needs_a_controller_or_a_bus():
    lean = quadcosim.Batch(noisy_hover(), 2, threads=1, plant_only=True)
    with pytest.raises(ValueError, match=r"plant_only .*give omega_cmd.*nothing was stepped"):
        lean.step()
    assert np.array_equal(lean.tick, [0, 0])
    with pytest.raises(ValueError, match=r"plant_only: it has no controllers"):
        lean.set_setpoints(z=3.0)
    assert list(lean.setpoints["z"]) == [2.0, 2.0]  # the scenario's
    assert np.array_equal(lean.reference["p"], [[0.0, 0.0, 2.0]] * 2)
    faulty = noisy_hover()
    faulty["message_faults"] = {"topics": {"motor_commands": {"drop_probability": 0.1}}}
    with pytest.raises(quadcosim.ConfigError, match=r"plant_only: the scenario injects message faults"):
        quadcosim.Batch(faulty, 2, plant_only=True)
    assert "plant_only" in repr(lean)


def _realism_hover():
    """realistic_hover without its rotor fault, which the position controller does not survive, and
    with an integral gain (the controller's period counts)."""
    d = realistic_hover()
    del d["faults"]
    d["controller"]["position"] = {"ki": 0.05}
    return d


def _faulty_hover():
    d = noisy_hover()
    d["message_faults"] = {"topics": {"motor_commands": {"drop_probability": 0.2},
                                      "Imu": {"delay_ticks": 1}}}
    return d


def _sensors_hover():
    """The noisy hover with a magnetometer, a barometer and a GNSS receiver (the GNSS slow, late and
    without a fix for its first 0.5 s), and message faults on the Imu: whole Simulations."""
    d = noisy_hover()
    d["environment"] = {"site": {"latitude_deg": 47.397742, "longitude_deg": 8.545594, "altitude_m": 488}}
    d["sensors"].update({
        "magnetometer": {"rate_hz": 50, "noise_sigma_uT": 0.3, "hard_iron_uT": [1.0, -2.0, 0.5]},
        "barometer": {"rate_hz": 25, "noise_sigma_Pa": 1.2, "drift_Pa_sqrt_s": 0.1, "bias_initial_Pa": 20},
        "gnss": {"rate_hz": 10, "latency_ticks": 5, "horizontal_sigma_m": 0.8, "vertical_sigma_m": 1.5,
                 "velocity_sigma_m_s": 0.05, "fix_after_s": 0.5}})
    d["message_faults"] = {"topics": {"Imu": {"delay_ticks": 1}}}
    return d


PATHS = {  # scenario, and whether a Batch flies it without a bus (else whole Simulations)
    "schedule": ("scenarios/swarm/grid_takeoff.yaml", True),  # position mode, z_des set by its schedule
    "trajectory": ("scenarios/tracking/figure8_se3.yaml", True),  # the SE(3) controller on a figure 8
    "realism": (_realism_hover(), True),  # noise, rates, latency, wind and gusts, drag, motor lag, a delay
    "faults": (_faulty_hover(), False),  # injected message faults act on the bus
    "sensors": ("scenarios/realism/all_sensors.yaml", True),  # magnetometer, barometer, GNSS too
    "sensors_faults": (_sensors_hover(), False),  # the same on whole Simulations
}


@pytest.mark.parametrize("case", sorted(PATHS))
def test_every_kind_of_vehicle_equals_its_single_simulation(case, tmp_path):
    """Controllers flying, rotor commands from Python (the controller still taking its samples), the
    controllers again, setpoints changed, several periods per call: bit for bit a single Simulation."""
    scenario, lean = PATHS[case]
    n = 3
    seeds = [5, 6, 2**33 + 1]
    # The third has products of inertia: the model's whole-tensor path (docs/model.md).
    vehicles = [None, {"mass_kg": 0.47}, {"Izz_kg_m2": 0.012, "Ixy_kg_m2": 0.001, "Iyz_kg_m2": -0.0005}]
    batch = quadcosim.Batch(quadcosim.load_scenario(scenario), n, seeds=seeds, vehicles=vehicles, threads=2)
    assert batch._b.lean_vehicles() == lean
    singles = []
    for i, (v, s) in enumerate(zip(vehicles, seeds)):
        if v is None:
            sc = quadcosim.load_scenario(scenario)
        elif isinstance(scenario, dict):
            d = copy.deepcopy(scenario)
            d.setdefault("vehicle", {}).update(v)
            sc = quadcosim.load_scenario(d)
        else:  # a file without a vehicle section: the section added
            path = tmp_path / f"vehicle{i}.yaml"
            path.write_text(_quadcosim._replace_sections(quadcosim.load_scenario(scenario).yaml(), repr({"vehicle": v})))
            sc = quadcosim.load_scenario(path)
        singles.append(quadcosim.Simulation(sc, seed=s))
    hover = batch.vehicle_params["hover_omega_rad_s"]
    rng = np.random.default_rng(3)
    for k in range(70):
        if k == 20:
            batch.set_setpoints([0, 2], z=[1.5, 3.0], yaw=[0.0, 0.3])
            singles[0].set_setpoint(z=1.5, yaw=0.0)
            singles[2].set_setpoint(z=3.0, yaw=0.3)
        periods = 3 if k % 9 == 4 else 1
        if 30 <= k < 40:
            cmd = hover[:, None] * (1.0 + rng.uniform(-0.02, 0.02, size=(n, 4)))
            batch.step(omega_cmd=cmd, periods=periods)
            for i, sim in enumerate(singles):
                for _ in range(periods):
                    sim.step(omega_cmd=cmd[i])
        else:
            batch.step(periods=periods)
            for sim in singles:
                for _ in range(periods):
                    sim.step()
        if k % 10 == 9:
            for i, sim in enumerate(singles):
                assert_same(snapshot_single(sim), snapshot_row(batch, i), f"{case}: vehicle {i} step {k}")
    # The vehicles flew, and differently (else equality would prove little).
    assert np.all(batch.p[:, 2] > 0.5), batch.p
    if case.startswith("sensors"):  # the extra sensors were compared, with a GNSS fix by now
        row = snapshot_row(batch, 1)
        assert np.all(np.isfinite(row["gnss.latitude_deg"])) and row["gnss.fix"] == 1.0, row
        assert {"magnetometer.field", "barometer.altitude", "gnss.v"} <= set(row)
    assert not np.array_equal(batch.p[0], batch.p[2])


# --- Box ------------------------------------------------------------------------------------------------


def test_box():
    box = Box(-1.0, 2.0, (3, 4), dtype=np.float32, seed=4)
    s = box.sample()
    assert s.shape == (3, 4) and s.dtype == np.float32 and box.contains(s) and s in box
    assert np.array_equal(Box(-1.0, 2.0, (3, 4), seed=4).sample(), s)  # seeded: repeatable
    assert not box.contains(np.zeros((4, 3), np.float32))
    assert not box.contains(np.full((3, 4), 2.5, np.float32))
    assert box.contains(np.zeros((3, 4), np.float32)) and not box.contains(np.zeros((3, 4), np.complex128))
    half = Box(np.array([0.0, -np.inf]), np.array([np.inf, np.inf]))
    assert half.shape == (2,) and half.contains(half.sample()) and not half.is_bounded()
    with pytest.raises(ValueError):
        Box(1.0, 0.0, (2,))


# --- environments -----------------------------------------------------------------------------------------


def hover_action(env_batch, i=0):
    """The normalised action of the hover speed omega_h = sqrt(m g / (4 k_t)), from the vehicle's parameters."""
    vp = env_batch.vehicle_params
    omega_h = math.sqrt(vp["mass_kg"][i] * vp["gravity_m_s2"][i] / (4 * vp["kt_N_per_rad2_s2"][i]))
    lo, hi = vp["motor.omega_min_rad_s"][i], vp["motor.omega_max_rad_s"][i]
    return 2 * (omega_h - lo) / (hi - lo) - 1


def check_obs(space, obs):
    assert isinstance(obs, np.ndarray) and obs.dtype == space.dtype and obs.shape == space.shape
    assert space.contains(obs)


@pytest.mark.parametrize("make", [HoverEnv, TrackingEnv])
def test_env_contract(make):
    env = make()
    assert env.observation_space.shape == (18,) and env.action_space.shape == (4,)
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(4))
    out = env.reset(seed=0)
    assert isinstance(out, tuple) and len(out) == 2
    obs, info = out
    check_obs(env.observation_space, obs)
    assert isinstance(info, dict)
    np.testing.assert_allclose(obs[:6], 0.0, atol=1e-12)  # starts on its reference, at rest
    np.testing.assert_allclose(obs[6:15], np.eye(3).ravel(), atol=1e-12)  # level
    env.action_space.seed(1)
    for _ in range(50):
        out = env.step(env.action_space.sample())
        assert isinstance(out, tuple) and len(out) == 5
        obs, reward, terminated, truncated, info = out
        check_obs(env.observation_space, obs)
        assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
        assert isinstance(info, dict) and {"t", "crashed", "out_of_bounds", "omega_cmd"} <= set(info)
        if terminated or truncated:
            break
    with pytest.raises(ValueError, match=r"shape \(4,\)"):
        env.reset()
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([0.0, np.nan, 0.0, 0.0]))


def test_actions_map_to_the_rotor_range():
    env = HoverEnv(scenario=noisy_hover({"motor": {"omega_min_rad_s": 100.0, "omega_max_rad_s": 9000.0}}))
    env.reset(seed=0)
    *_, info = env.step(np.array([-1.0, 1.0, 0.0, 3.0]))  # 3 is clipped to 1
    np.testing.assert_allclose(info["omega_cmd"], [100.0, 9000.0, 4550.0, 9000.0])


def test_hovering_speeds_keep_the_hover_env_alive():
    env = HoverEnv(max_episode_steps=300)
    env.reset(seed=0)
    a = np.full(4, hover_action(env.batch))
    total = 0.0
    for _ in range(250):
        obs, reward, terminated, truncated, info = env.step(a)
        assert not terminated and not truncated
        assert reward > 0.99
        total += reward
    assert total > 0.99 * 250
    assert np.max(np.abs(obs[:3])) < 0.01  # stayed within 1 cm of the target


def test_reset_seed_is_deterministic_and_randomises_the_vehicle():
    def episode(seed):
        env = HoverEnv(scenario=noisy_hover(), randomize={"mass_kg": (0.4, 0.55), "motor.tau_up_s": (0.01, 0.05)})
        obs, _ = env.reset(seed=seed)
        mass = env.batch.vehicle_params["mass_kg"][0]
        rng = np.random.default_rng(123)
        seq = [obs]
        a_h = hover_action(env.batch)
        for _ in range(30):
            obs, _, terminated, _, _ = env.step(a_h + rng.uniform(-0.005, 0.005, 4))
            assert not terminated
            seq.append(obs)
        return mass, np.array(seq)

    m1, s1 = episode(7)
    m2, s2 = episode(7)
    m3, s3 = episode(8)
    assert m1 == m2 and np.array_equal(s1, s2)
    assert 0.4 <= m1 <= 0.55 and m3 != m1 and not np.array_equal(s1, s3)


def test_terminated_and_truncated():
    env = HoverEnv(max_episode_steps=20)
    env.reset(seed=0)
    a = np.full(4, hover_action(env.batch))
    for k in range(1, 21):
        _, _, terminated, truncated, _ = env.step(a)
        assert not terminated and truncated == (k == 20)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(a)
    # Rotors at their lowest speed: it falls from 1 m and crashes.
    env = HoverEnv(max_episode_steps=1000, termination_penalty=10.0)
    env.reset(seed=0)
    for k in range(200):
        _, reward, terminated, truncated, info = env.step(-np.ones(4))
        if terminated:
            break
    assert terminated and info["crashed"] and not truncated and reward < -9
    assert info["t"] == pytest.approx(math.sqrt(2 * 1.0 / 9.81), abs=0.1)  # free fall from 1 m (rotor drag aside)
    # A target 1.5 m away with a 1 m box: out of bounds at once.
    env = HoverEnv(max_position_error_m=1.0)
    env.reset(seed=0, options={"target": [0.0, 0.0, 2.5]})
    _, _, terminated, _, info = env.step(np.full(4, hover_action(env.batch)))
    assert terminated and info["out_of_bounds"] and not info["crashed"]


def test_tracking_env_follows_the_circle():
    env = TrackingEnv()
    env.reset(seed=0)
    for _ in range(150):
        env.step(np.full(4, hover_action(env.batch)))
    ref = env.batch.reference
    # The reference is on the circle (radius 1 m about (0, 0) at 1 m): an independent check of the trajectory.
    assert math.hypot(ref["p"][0, 0], ref["p"][0, 1]) == pytest.approx(1.0, abs=1e-9)
    assert ref["p"][0, 2] == pytest.approx(1.0)
    obs, *_ = env.step(np.full(4, hover_action(env.batch)))
    ref = env.batch.reference
    np.testing.assert_allclose(obs[:3], (env.batch.p - ref["p"])[0], rtol=1e-6)
    # A trajectory given replaces the scenario's; a scenario without one is refused.
    env = TrackingEnv(trajectory={"kind": "circle", "centre_m": [0, 0], "altitude_m": 1, "radius_m": 1,
                                  "period_s": 4, "ramp_s": 1, "yaw_mode": "fixed"})
    env.reset(seed=0)
    with pytest.raises(ValueError, match="no trajectory"):
        TrackingEnv(scenario=noisy_hover())
    # A scenario file of scenarios/tracking: its trajectory, from its start point.
    env = TrackingEnv(scenario="scenarios/tracking/figure8_paper.yaml")
    obs, _ = env.reset(seed=0)
    np.testing.assert_allclose(obs[:6], 0.0, atol=1e-9)
    obs, *_ = env.step(np.full(4, hover_action(env.batch)))
    check_obs(env.observation_space, obs)


def test_vector_env_equals_single_envs():
    """Sub-env i of a vector env reset with seed s flies what HoverEnv reset with seed s + i flies."""
    kw = dict(scenario=noisy_hover(), randomize={"mass_kg": (0.4, 0.55)})
    venv = VectorHoverEnv(3, **kw)
    assert venv.observation_space.shape == (3, 18) and venv.action_space.shape == (3, 4)
    obs, info = venv.reset(seed=10)
    check_obs(venv.observation_space, obs)
    rng = np.random.default_rng(0)
    actions = hover_action(venv.batch) + rng.uniform(-0.005, 0.005, size=(20, 3, 4))
    seq = [obs]
    for a in actions:
        obs, reward, terminated, truncated, info = venv.step(a)
        assert not np.any(terminated | truncated)
        assert obs.dtype == np.float32 and reward.shape == (3,) and terminated.dtype == bool
        assert truncated.dtype == bool and info["t"].shape == (3,)
        seq.append(obs)
    for i in range(3):
        env = HoverEnv(**kw)
        o, _ = env.reset(seed=10 + i)
        single = [o]
        for a in actions:
            o, *_ = env.step(a[i])
            single.append(o)
        assert np.array_equal(np.array(single), np.array(seq)[:, i]), f"sub-env {i}"


def test_envs_fly_the_plants_alone_with_the_numbers_of_the_full_vehicles():
    """The envs step Batch(plant_only=True); a scenario with message faults needs the bus and gets the
    full vehicles. Faults on /clock change nothing a Batch's vehicle computes (it publishes no /clock),
    so both fly the same numbers."""
    lean_env = VectorHoverEnv(3, scenario=noisy_hover(), randomize={"mass_kg": (0.4, 0.55)})
    faulty = noisy_hover()
    faulty["message_faults"] = {"topics": {"clock": {"drop_probability": 0.5}}}
    full_env = VectorHoverEnv(3, scenario=faulty, randomize={"mass_kg": (0.4, 0.55)})
    assert lean_env.batch.plant_only and not full_env.batch.plant_only
    a, _ = lean_env.reset(seed=5)
    b, _ = full_env.reset(seed=5)
    assert np.array_equal(a, b)
    rng = np.random.default_rng(3)
    for action in hover_action(lean_env.batch) + rng.uniform(-0.01, 0.01, size=(30, 3, 4)):
        ra = lean_env.step(action)
        rb = full_env.step(action)
        for x, y in zip(ra[:4], rb[:4]):
            assert np.array_equal(x, y)
    assert_same_bits(every_array(lean_env.batch), every_array(full_env.batch), "after 30 steps")


def test_vector_env_next_step_autoreset():
    venv = VectorHoverEnv(3, max_episode_steps=1000)
    first, _ = venv.reset(seed=0)
    a = np.tile(hover_action(venv.batch), (3, 4))
    a[1] = -1.0  # sub-env 1 falls
    for k in range(200):
        obs, reward, terminated, truncated, info = venv.step(a)
        if terminated[1]:
            break
    assert terminated[1] and info["crashed"][1] and not terminated[0] and not terminated[2]
    t_end = info["t"].copy()
    obs, reward, terminated, truncated, info = venv.step(a)  # sub-env 1 resets, its action ignored
    assert reward[1] == 0.0 and not terminated[1] and not truncated[1]
    assert np.array_equal(obs[1], first[1]) and info["t"][1] == 0.0
    assert info["t"][0] == pytest.approx(t_end[0] + 0.02) and reward[0] > 0.99
    obs, reward, terminated, truncated, info = venv.step(a)
    assert info["t"][1] == pytest.approx(0.02)  # it flies again


def test_vector_env_same_step_autoreset():
    venv = VectorHoverEnv(2, max_episode_steps=5, autoreset_mode="same_step")
    first, _ = venv.reset(seed=0)
    a = np.tile(hover_action(venv.batch), (2, 4))
    for k in range(1, 6):
        obs, reward, terminated, truncated, info = venv.step(a)
    assert np.all(truncated) and np.all(info["_final_obs"])
    assert np.array_equal(obs, first) and np.all(venv.batch.t == 0.0)  # reset in the same step
    assert np.all(np.isfinite(info["final_obs"]))
    obs, reward, terminated, truncated, info = venv.step(a)
    assert not np.any(info["_final_obs"]) and np.all(reward > 0.99)


def test_vector_tracking_env_runs():
    venv = VectorTrackingEnv(4, threads=2)
    obs, _ = venv.reset(seed=1)
    for _ in range(10):
        obs, reward, terminated, truncated, info = venv.step(venv.action_space.sample() * 0.05 - 0.2)
    check_obs(venv.observation_space, obs)
    with pytest.raises(ValueError, match="shape"):
        venv.step(np.zeros((3, 4)))


def test_nominal_controller_sags_by_the_closed_form():
    """controller_vehicle="nominal": the paper's altitude PD (u = m_nom g + K_p,z e - K_d,z v_z, no
    integral) holds a vehicle of mass m below its setpoint by e = (m - m_nom) g / K_p,z; designed for the
    vehicle's own mass ("own") it holds it on the setpoint."""
    masses = np.array([1.7, 1.96, 2.2])
    kp, g, m_nom = 4.0, 9.81, 1.96  # altitude.kp's default [N/m] and the paper's vehicle (docs/controllers.md)
    for mode, expected in (("nominal", (masses - m_nom) * g / kp), ("own", np.zeros(3))):
        b = quadcosim.Batch("scenarios/paper/altitude_step.yaml", 3, vehicles={"mass_kg": masses},
                            controller_vehicle=mode, threads=1)
        b.step(periods=2000)  # 40 s: long settled
        np.testing.assert_allclose(10.0 - b.p[:, 2], expected, atol=1e-6, err_msg=mode)
