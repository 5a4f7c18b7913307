"""Controllers written in Python, flown in process (quadcosim.run and quadcosim.Simulation with
controller=..., and scenarios with controller: {python: "module:Class"}): closed-loop behaviour against
bounds derived from the gains, a line-by-line port of the C++ example_pd controller against the C++
controller bit for bit, parameters, schedules, every kind of bad return value, time limits and
determinism. Run by tests/python/run_pytest.sh (CTest python.pytest)."""

import filecmp
import hashlib
import json
import math
import os
import pathlib
import textwrap
import threading
import time

import numpy as np
import pytest

import quadcosim

SOURCE = pathlib.Path(os.environ.get("QUADCOSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
ALTITUDE_STEP = "scenarios/paper/altitude_step.yaml"

# The plant's state and the commands it latched: what a controller decides, whatever it reports.
STATE = ["x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r", "w1", "w2", "w3", "w4",
         "cmd1", "cmd2", "cmd3", "cmd4"]


@pytest.fixture(autouse=True)
def _in_source_dir(monkeypatch):
    monkeypatch.chdir(SOURCE)


def hover_scenario(z0=1.0, duration_s=10.0, **controller):
    """A trimmed hover at z0 (rotors at hover speed) with no noise, the controller asked to hold z0."""
    return {
        "name": "hover",
        "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": duration_s},
        "initial": {"position_m": [0.0, 0.0, z0], "hover": True},
        "controller": {"mode": "attitude", "z_des": z0, **controller},
    }


class AltitudePD:
    """Altitude PD with gravity feedforward: the vertical acceleration a = kp (z_des - z) - kd vz is made
    exactly (for a level vehicle) by the collective thrust m (g + a) shared by four equal rotors. The
    closed loop is z'' = kp (z_des - z) - kd z': natural frequency sqrt(kp), damping kd / (2 sqrt(kp))."""

    parameters = {
        "kp_z": dict(default=1.0, unit="1/s^2", min=0.0, max=100.0, description="acceleration per metre"),
        "kd_z": dict(default=1.4, unit="1/s", min=0.0, max=100.0, description="acceleration per m/s"),
    }
    outputs = ("error.z",)

    def __init__(self, vehicle):
        self.m = vehicle["mass_kg"]
        self.g = vehicle["gravity_m_s2"]
        self.kt = vehicle["kt_N_per_rad2_s2"]

    def step(self, obs, ref, dt):
        e = float(ref.p[2] - obs.p[2])
        a = self.kp_z * e - self.kd_z * float(obs.v[2])
        w = math.sqrt(max(self.m * (self.g + a), 0.0) / (4.0 * self.kt))
        return (w, w, w, w), (e,)


def step_figures(t, z, z0, z1):
    """Overshoot [fraction of the step], peak time [s] and the last time |z - z1| exceeded 2 % of the step."""
    step = z1 - z0
    peak = int(np.argmax(z))
    outside = np.nonzero(np.abs(z - z1) > 0.02 * abs(step))[0]
    return (z[peak] - z1) / step, t[peak], t[outside[-1]] if len(outside) else 0.0


# --- closed-loop behaviour ----------------------------------------------------------------------------


def test_a_python_pd_holds_a_hover():
    """From the trimmed hover the PD commands exactly the hover thrust (zero error, zero velocity): the
    vehicle stays put up to rounding (1e-9 m over 10 s), and the figures it returns are its errors."""
    r = quadcosim.run(hover_scenario(z0=1.0), controller=AltitudePD)
    tr = r.trajectory
    assert np.max(np.abs(tr["z"] - 1.0)) < 1e-9
    assert np.max(np.abs(tr["x"])) == 0.0 and np.max(np.abs(tr["y"])) == 0.0
    assert np.all(tr["qx"] == 0.0) and np.all(tr["qy"] == 0.0)


def test_a_python_pd_flies_the_altitude_step_as_its_gains_say():
    """The paper's altitude step (0 -> 10 m at t = 0, from the ground) with kp = 1 /s^2, kd = 1.4 /s:
    wn = 1 rad/s, zeta = 0.7. A second-order loop overshoots by exp(-pi zeta / sqrt(1 - zeta^2)) = 4.6 %
    at pi / (wn sqrt(1 - zeta^2)) = 4.40 s, and stays within 2 % once its envelope
    exp(-zeta wn t) / sqrt(1 - zeta^2) is below 0.02: after 6.07 s. The 50 Hz sampling and the sensor
    sample's age add a few hundredths of a second of lag (a little more overshoot), hence the bands. The
    thrust asked never exceeds what the rotors give (|a| <= kp * 10 m), so the loop is linear."""
    r = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD)
    t, z = r.trajectory["t"], r.trajectory["z"]
    zeta, wn = 0.7, 1.0
    overshoot, peak_time, settled = step_figures(t, z, 0.0, 10.0)
    expected_overshoot = math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))
    expected_peak = math.pi / (wn * math.sqrt(1 - zeta**2))
    expected_settling = math.log(1 / (0.02 * math.sqrt(1 - zeta**2))) / (zeta * wn)
    assert expected_overshoot == pytest.approx(0.046, abs=0.001)
    assert expected_overshoot - 0.005 < overshoot < expected_overshoot + 0.015
    assert abs(peak_time - expected_peak) < 0.25
    assert settled < expected_settling + 0.3
    assert abs(z[-1] - 10.0) < 0.005  # the envelope at 15 s: 10 m * 1.4 exp(-10.5) = 0.4 mm
    assert np.all(np.isfinite(r.trajectory["cmd1"]))
    # The status: U1 is the thrust of the commanded speeds (the FMU controller's convention), the attitude
    # error is not known.
    assert np.all(np.isnan(r.trajectory["att_err"]))


def test_gains_from_the_scenario_change_the_loop():
    """kp_z = 4 /s^2, kd_z = 5.6 /s as scenario keys: wn = 2 rad/s, zeta = 5.6 / (2 * 2) = 1.4, overdamped:
    no overshoot at all, and faster at first than the default gains (wn = 1). The first thrust asked,
    m (g + 4 * 10 m/s^2) = 98 N, is below the rotors' 119 N."""
    sc = quadcosim.load_scenario(ALTITUDE_STEP)
    doc = {"simulation": {"duration_s": 15}, "controller": {"mode": "attitude", "z_des": 0, "kp_z": 4.0, "kd_z": 5.6},
           "schedule": [{"at_s": 0, "set": {"z_des": 10.0}}]}
    fast = quadcosim.run(doc, controller=AltitudePD)
    z = fast.trajectory["z"]
    assert np.max(z) <= 10.0
    assert abs(z[-1] - 10.0) < 0.005
    slow = quadcosim.run(sc, controller=AltitudePD)
    i = int(np.argmax(slow.trajectory["t"] >= 2.0))
    assert z[i] > slow.trajectory["z"][i]


def test_class_and_instance_fly_the_same_trajectory():
    """The same controller given as its class (quadcosim instantiates it with the vehicle) and as an
    instance made with Scenario.vehicle: the same doubles in every column."""
    sc = quadcosim.load_scenario(ALTITUDE_STEP)
    by_class = quadcosim.run(sc, controller=AltitudePD)
    by_instance = quadcosim.run(sc, controller=AltitudePD(sc.vehicle))
    for name in by_class.trajectory:
        assert np.array_equal(by_class.trajectory[name], by_instance.trajectory[name], equal_nan=True), name


def test_the_object_passed_is_not_stepped():
    """Each run flies a copy.deepcopy of the configured object: an instance counting its steps is still
    at 0 afterwards, and two runs of it are the same."""

    class Counting(AltitudePD):
        def __init__(self, vehicle):
            super().__init__(vehicle)
            self.n = 0

        def step(self, obs, ref, dt):
            self.n += 1
            return super().step(obs, ref, dt)

    sc = quadcosim.load_scenario(hover_scenario(duration_s=1.0))
    c = Counting(sc.vehicle)
    quadcosim.run(sc, controller=c)
    assert c.n == 0


# --- a port of the C++ example controller, bit for bit --------------------------------------------------


def wrap_pi(a):
    """model::wrap_pi (src/model/angle.hpp), line by line."""
    if -math.pi < a <= math.pi:
        return a
    if not math.isfinite(a):
        return a
    r = math.remainder(a, 2.0 * math.pi)
    return r + 2.0 * math.pi if r <= -math.pi else r


class ExamplePdPort:
    """src/controllers/example_pd/example_pd_controller.cpp in Python, operation by operation (the same
    IEEE doubles in the same order; the build has no fused multiply-add, -ffp-contract=off), with the
    allocation of control/allocation.cpp over the vehicle's mixer_inverse (Eigen's product sums each row
    left to right)."""

    parameters = {
        "position.kp": dict(default=1.0, unit="1/s^2", min=0, max=1e3),
        "position.kd": dict(default=1.6, unit="1/s", min=0, max=1e3),
        "attitude.kp": dict(default=64.0, unit="1/s^2", min=0, max=1e5),
        "attitude.kd": dict(default=12.0, unit="1/s", min=0, max=1e4),
        "max_tilt": dict(default=0.5, unit="rad", min=0.01, max=1.2),
    }
    outputs = ("thrust_N",)

    def __init__(self, vehicle):
        self.vehicle = vehicle

    def step(self, o, r, dt):
        v = self.vehicle
        kp, kd = getattr(self, "position.kp"), getattr(self, "position.kd")
        g = v["gravity_m_s2"]
        a = [kp * (r.p[i] - o.p[i]) + kd * (r.v[i] - o.v[i]) + r.a[i] for i in range(3)]
        roll_des, pitch_des = r.roll, r.pitch
        if r.mode == "position":
            c, s = math.cos(o.yaw), math.sin(o.yaw)
            pitch_des = (a[0] * c + a[1] * s) / g
            roll_des = (a[0] * s - a[1] * c) / g
            roll_des = min(max(roll_des, -self.max_tilt), self.max_tilt)
            pitch_des = min(max(pitch_des, -self.max_tilt), self.max_tilt)
        tilt = max(math.cos(o.roll) * math.cos(o.pitch), 0.5)
        u0 = v["mass_kg"] * (g + a[2]) / tilt
        e = (roll_des - o.roll, pitch_des - o.pitch, wrap_pi(r.yaw - o.yaw))
        J = (v["Ixx_kg_m2"], v["Iyy_kg_m2"], v["Izz_kg_m2"])
        akp, akd = getattr(self, "attitude.kp"), getattr(self, "attitude.kd")
        U = (u0,) + tuple(J[i] * (akp * e[i] - akd * o.w[i]) for i in range(3))
        lo = v["motor.omega_min_rad_s"] * v["motor.omega_min_rad_s"]
        hi = v["motor.omega_max_rad_s"] * v["motor.omega_max_rad_s"]
        omega = []
        for m in v["mixer_inverse"]:
            w2 = ((m[0] * U[0] + m[1] * U[1]) + m[2] * U[2]) + m[3] * U[3]
            omega.append(math.sqrt(max(0.0, min(max(w2, lo), hi))))
        return omega, (u0,)


@pytest.mark.parametrize("case", ["altitude_step", "position_steps"])
def test_a_python_port_of_example_pd_flies_its_trajectory_bit_for_bit(case):
    if case == "altitude_step":
        doc = {"simulation": {"duration_s": 15}, "controller": {"type": "example_pd", "mode": "attitude", "z_des": 0},
               "schedule": [{"at_s": 0, "set": {"z_des": 10.0}}]}
    else:
        # Position mode: tilts, and the tilt bound (a 3 m step asks 3 m/s^2 at first: 0.3 rad > 0.2), a
        # gain change mid-run. (No yaw step: the paper's vehicle has so little yaw authority, k_m / k_t =
        # 5e-4 m, that this example's attitude gains saturate every rotor for any yaw error of note.)
        doc = {"simulation": {"duration_s": 12}, "initial": {"position_m": [0, 0, 1], "hover": True},
               "controller": {"type": "example_pd", "mode": "position", "z_des": 1.0, "max_tilt": 0.2},
               "schedule": [{"at_s": 1, "set": {"x_des": 3.0, "y_des": -1.0, "z_des": 2.0}},
                            {"at_s": 6, "set": {"position.kp": 1.5}}]}
    cpp = quadcosim.run(doc)
    port = quadcosim.run(doc, controller=ExamplePdPort)
    for name in STATE:
        assert np.array_equal(cpp.trajectory[name], port.trajectory[name]), name
    if case == "position_steps":
        # It did fly there, through the tilt bound.
        assert np.sum(cpp.trajectory["tilt_sat"]) > 10
        assert abs(cpp.trajectory["x"][-1] - 3.0) < 0.01 and abs(cpp.trajectory["y"][-1] + 1.0) < 0.01


# --- parameters --------------------------------------------------------------------------------------------


def test_declared_parameters_are_scenario_keys_with_range_checks():
    bad = hover_scenario(kp_z=200.0)
    with pytest.raises(quadcosim.ConfigError) as e:
        quadcosim.run(bad, controller=AltitudePD)
    assert "controller.kp_z" in str(e.value) and "200" in str(e.value) and "[0, 100]" in str(e.value)
    with pytest.raises(quadcosim.ConfigError, match=r"controller\.kp_zz.*unknown parameter 'kp_zz'"):
        quadcosim.run(hover_scenario(kp_zz=1.0), controller=AltitudePD)
    with pytest.raises(quadcosim.ConfigError, match=r"controller\.kd_z.*fast.*number"):
        quadcosim.run(hover_scenario(kd_z="fast"), controller=AltitudePD)


def test_parameter_values_reach_the_object_as_attributes():
    seen = []

    class Probe(AltitudePD):
        def step(self, obs, ref, dt):
            seen.append((self.kp_z, self.kd_z))
            return super().step(obs, ref, dt)

    quadcosim.run(hover_scenario(duration_s=0.1, kp_z=2.5), controller=Probe)
    assert seen and all(s == (2.5, 1.4) for s in seen)


class Switching(AltitudePD):
    """AltitudePD that changes kd_z itself at its 250th step (t = 5 s), as a schedule would."""

    def __init__(self, vehicle):
        super().__init__(vehicle)
        self.n = 0

    def step(self, obs, ref, dt):
        if self.n == 250:
            self.kd_z = 3.0
        self.n += 1
        return super().step(obs, ref, dt)


def test_a_schedule_changes_a_declared_parameter_mid_run():
    """schedule: kd_z = 3 at t = 5 s gives exactly the trajectory of a controller that switches kd_z
    itself at its step at 5 s (the schedule applies before the step of its tick), and not that of the
    unchanged one."""
    doc = {"simulation": {"duration_s": 10}, "controller": {"mode": "attitude", "z_des": 0},
           "schedule": [{"at_s": 0, "set": {"z_des": 10.0}}, {"at_s": 5, "set": {"kd_z": 3.0}}]}
    scheduled = quadcosim.run(doc, controller=AltitudePD).trajectory
    switching = quadcosim.run({**doc, "schedule": doc["schedule"][:1]}, controller=Switching).trajectory
    unchanged = quadcosim.run({**doc, "schedule": doc["schedule"][:1]}, controller=AltitudePD).trajectory
    for name in STATE:
        assert np.array_equal(scheduled[name], switching[name]), name
    t = scheduled["t"]
    before = t <= 5.0
    assert np.array_equal(scheduled["z"][before], unchanged["z"][before])
    assert not np.array_equal(scheduled["z"], unchanged["z"])


def test_set_parameters_may_refuse_a_change():
    """A class's set_parameters raising ValueError refuses the change: a schedule asking it is a
    ConfigError naming the entry, the parameter and the class's reason; an accepted one is passed to it
    before the attribute changes."""
    calls = []

    class Picky(AltitudePD):
        def set_parameters(self, changes):
            calls.append((dict(changes), self.kd_z))
            if changes.get("kd_z", 0.0) > 5.0:
                raise ValueError("kd_z above 5 /s makes the motors chatter")

    doc = {"simulation": {"duration_s": 2}, "controller": {"mode": "attitude", "z_des": 1, "kd_z": 2.0},
           "schedule": [{"at_s": 1, "set": {"kd_z": 6.0}}]}
    with pytest.raises(quadcosim.ConfigError) as e:
        quadcosim.run(doc, controller=Picky)
    assert "schedule[0].set.kd_z" in str(e.value) and "chatter" in str(e.value) and "Picky" in str(e.value)
    assert calls[0] == ({"kd_z": 2.0}, 1.4)  # the scenario's value, offered while the attribute was the default
    calls.clear()
    doc["schedule"][0]["set"]["kd_z"] = 4.0
    quadcosim.run(doc, controller=Picky)
    assert ({"kd_z": 4.0}, 2.0) in calls


def test_bad_declarations_are_refused_by_name():
    class NoStep:
        pass

    class BadRange(AltitudePD):
        parameters = {"k": dict(default=5.0, min=0.0, max=1.0)}

    class NodeName(AltitudePD):
        parameters = {"z_des": dict(default=1.0)}

    class UnknownField(AltitudePD):
        parameters = {"k": dict(default=1.0, maximum=2.0)}

    sc = quadcosim.load_scenario(hover_scenario())
    for cls, pattern in [(NoStep, r"NoStep: has no method step"), (BadRange, r"parameters\['k'\].*k must be in \[0, 1\]"),
                         (NodeName, r"parameters\['z_des'\].*node"), (UnknownField, r"unknown key 'maximum'")]:
        with pytest.raises(quadcosim.ConfigError, match=pattern):
            quadcosim.run(sc, controller=cls)


# --- bad input: ControllerError naming the class, the step and its time ------------------------------------


def failing(after, value=None, exc=None, outputs=()):
    """A hover controller that returns `value` (or raises `exc`) from its step number `after` on."""

    class Failing:
        def __init__(self, vehicle):
            self.w = vehicle["hover_omega_rad_s"]
            self.n = 0

        def step(self, obs, ref, dt):
            self.n += 1
            if self.n > after:
                if exc is not None:
                    raise exc
                return value
            return (self.w,) * 4 if not outputs else ((self.w,) * 4, (0.0,) * len(outputs))

    Failing.outputs = outputs
    return Failing


@pytest.mark.parametrize("value, message", [
    ([400.0, 400.0, 400.0], r"returned 3 values, expected 4 rotor speeds"),
    (np.full(3, 400.0), r"returned shape \(3,\), expected 4 rotor speeds"),
    (np.full((2, 2), 400.0), r"returned shape \(2, 2\), expected 4 rotor speeds"),
    (None, r"returned None, expected 4 rotor speeds"),
    (400.0, r"returned float \(400.0\), expected 4 rotor speeds"),
    ("fast", r"returned str \('fast'\), expected 4 rotor speeds"),
    ([400.0, "400", 400.0, 400.0], r"returned str \('400'\) as entry 1"),
    ([400.0, None, 400.0, 400.0], r"returned NoneType \(None\) as entry 1"),
    ([400.0, 400.0, 1j, 400.0], r"returned complex .* as entry 2"),
    (np.array(["a", "b", "c", "d"]), r"dtype <U1"),
    ([400.0, float("nan"), 400.0, 400.0], r"returned rotor speed 2 = nan; not commanded"),
    ((400.0, 400.0, 400.0, float("inf")), r"returned rotor speed 4 = inf; not commanded"),
    (np.array([400.0, 400.0, -np.inf, 400.0]), r"returned rotor speed 3 = -inf"),
])
def test_a_bad_return_value_is_a_controller_error_naming_step_and_time(value, message, tmp_path):
    cls = failing(after=12, value=value)
    with pytest.raises(quadcosim.ControllerError, match=message) as e:
        quadcosim.run(hover_scenario(), controller=cls, out=tmp_path / "run")
    text = str(e.value)
    assert text.startswith(f"{cls.__module__}.{cls.__qualname__}.step at step 12 (t = 0.24 s): "), text
    assert isinstance(e.value, RuntimeError)
    # Nothing non-finite reached the plant: every recorded command and state is finite.
    rows = (tmp_path / "run" / "trajectory.csv").read_text().splitlines()
    header = rows[0].split(",")
    data = np.array([[float(x) for x in row.split(",")] for row in rows[1:]])
    for name in STATE:
        assert np.all(np.isfinite(data[:, header.index(name)])), name


def test_an_exception_in_step_is_the_cause():
    cls = failing(after=3, exc=ZeroDivisionError("float division by zero"))
    with pytest.raises(quadcosim.ControllerError) as e:
        quadcosim.run(hover_scenario(), controller=cls)
    assert "step at step 3 (t = 0.06 s): raised ZeroDivisionError: float division by zero" in str(e.value)
    assert "test_controllers.py" in str(e.value)  # where it was raised
    assert isinstance(e.value.__cause__, ZeroDivisionError)
    assert e.value.__cause__.__traceback__ is not None


def test_a_batch_flies_a_python_controller_as_single_simulations_do():
    """Each vehicle its own instance, stepped from the batch's worker threads (each step takes the GIL):
    bit for bit the numbers of a single Simulation with that vehicle's keys."""
    masses = [None, 1.7, 2.3]
    def scenario(m):
        d = hover_scenario(z0=1.0)
        d["controller"]["z_des"] = 2.0
        if m:
            d["vehicle"] = {"mass_kg": m}
        return d
    batch = quadcosim.Batch(quadcosim.load_scenario(scenario(None), controller=AltitudePD), 3,
                            vehicles=[None if m is None else {"mass_kg": m} for m in masses], threads=2)
    singles = [quadcosim.Simulation(quadcosim.load_scenario(scenario(m), controller=AltitudePD)) for m in masses]
    for k in range(150):
        batch.step(periods=1 + k % 2)
        for s in singles:
            for _ in range(1 + k % 2):
                s.step()
    for i, s in enumerate(singles):
        for key in ("p", "v", "q", "w", "omega"):
            assert np.array_equal(batch.state[key][i], s.state[key]), (i, key)
    # The vehicles climbed to their setpoint, each with its own mass (else equality would prove little).
    assert np.all(np.abs(batch.p[:, 2] - 2.0) < 0.05)
    assert len({float(w) for w in batch.omega[:, 0]}) == 3


class RaisesAtItsFourthStep:
    """Hovers for three steps, then raises (module level: a Batch loads its vehicles' controllers by
    their module:Class name)."""

    def __init__(self, vehicle):
        self.w, self.n = vehicle["hover_omega_rad_s"], 0

    def step(self, obs, ref, dt):
        self.n += 1
        if self.n > 3:
            raise RuntimeError("boom")
        return (self.w,) * 4


def test_a_python_controller_that_raises_in_a_batch_is_named_with_its_step():
    batch = quadcosim.Batch(quadcosim.load_scenario(hover_scenario(), controller=RaisesAtItsFourthStep), 2, threads=2)
    batch.step(periods=3)
    with pytest.raises(quadcosim.ControllerError,
                       match=r"RaisesAtItsFourthStep.step at step 3 \(t = 0\.06 s\): raised RuntimeError: boom"):
        batch.step()


def test_outputs_of_the_wrong_length_or_missing_are_refused():
    with pytest.raises(quadcosim.ControllerError, match=r"returned 1 values, expected 2 outputs \(a, b\)"):
        quadcosim.run(hover_scenario(), controller=failing(after=0, value=((400.0,) * 4, (1.0,)), outputs=("a", "b")))
    with pytest.raises(quadcosim.ControllerError, match=r"returned omega alone, expected \(omega, outputs\)"):
        quadcosim.run(hover_scenario(), controller=failing(after=0, value=(400.0,) * 4, outputs=("a",)))
    with pytest.raises(quadcosim.ControllerError, match=r"declares no outputs"):
        quadcosim.run(hover_scenario(), controller=failing(after=0, value=((400.0,) * 4, (1.0,))))
    with pytest.raises(quadcosim.ControllerError, match=r"returned str \('x'\) as entry 0"):
        quadcosim.run(hover_scenario(), controller=failing(after=0, value=((400.0,) * 4, ("x",)), outputs=("a",)))


def test_outputs_may_be_any_numbers_even_not_finite():
    """The figures are recorded as returned (a controller may report NaN for "not known"); only the rotor
    speeds must be finite."""
    quadcosim.run(hover_scenario(duration_s=0.5),
                  controller=failing(after=0, value=((400.0,) * 4, (float("nan"), np.float32(2))), outputs=("a", "b")))


def test_numbers_of_any_numeric_type_are_accepted():
    for value in [[400, 400, 400, 400], np.full(4, 400, dtype=np.int32), np.full(4, 400.0, dtype=np.float32),
                  tuple(np.float64(400.0) for _ in range(4)), range(400, 404), [np.array(400.0)] * 4,
                  [np.float32(400.0)] * 4]:
        quadcosim.run(hover_scenario(duration_s=0.1), controller=failing(after=0, value=value))


@pytest.mark.parametrize("value, message", [
    ({1: 400.0, 2: 400.0, 3: 400.0, 4: 400.0}, r"returned dict"),
    ({400.0, 401.0, 402.0, 403.0}, r"returned set"),
    (iter([400.0] * 4), r"returned list_iterator"),
    ([True, 400.0, 400.0, 400.0], r"returned bool \(True\) as entry 0"),
])
def test_unordered_or_non_numeric_containers_are_refused(value, message):
    with pytest.raises(quadcosim.ControllerError, match=message):
        quadcosim.run(hover_scenario(), controller=failing(after=0, value=value))


def test_a_failing_init_or_deepcopy_is_named():
    class BadInit(AltitudePD):
        def __init__(self, vehicle):
            raise KeyError("no_such_key")

    with pytest.raises(quadcosim.ConfigError, match=r"controller\.python.*BadInit\(vehicle\) raised KeyError"):
        quadcosim.run(hover_scenario(), controller=BadInit)

    class Locked(AltitudePD):
        def __init__(self, vehicle):
            super().__init__(vehicle)
            self.lock = threading.Lock()

    with pytest.raises(quadcosim.ControllerError, match=r"Locked: copy\.deepcopy failed .*TypeError") as e:
        quadcosim.Simulation(quadcosim.load_scenario(hover_scenario()), controller=Locked)
    assert isinstance(e.value.__cause__, TypeError)


def test_keyboard_interrupt_in_a_step_passes_as_it_is():
    with pytest.raises(KeyboardInterrupt):
        quadcosim.run(hover_scenario(), controller=failing(after=5, exc=KeyboardInterrupt()))


# --- time limit ---------------------------------------------------------------------------------------------


class Stuck(AltitudePD):
    """Loops forever at its 10th step, swallowing every Exception on the way."""

    def __init__(self, vehicle):
        super().__init__(vehicle)
        self.n = 0

    def step(self, obs, ref, dt):
        self.n += 1
        while self.n >= 10:
            try:
                sum(range(1000))
            except Exception:
                pass
        return super().step(obs, ref, dt)


@pytest.mark.parametrize("where", ["call", "scenario", "class"])
def test_a_step_that_never_returns_is_stopped_by_its_time_limit(where):
    """step_timeout_s = 0.2 s (from the call, the scenario key or a class attribute): StepTimeout is raised
    inside the endless loop (through `except Exception`), the run ends with ControllerError at step 9."""
    kwargs, scenario, cls = {}, hover_scenario(), Stuck
    if where == "call":
        kwargs["step_timeout_s"] = 0.2
    elif where == "scenario":
        scenario = hover_scenario(step_timeout_s=0.2)
    else:
        cls = type("StuckWithLimit", (Stuck,), {"step_timeout_s": 0.2})
    start = time.perf_counter()
    with pytest.raises(quadcosim.ControllerError,
                       match=r"step at step 9 \(t = 0.18 s\): did not return within step_timeout_s = 0.2 s") as e:
        quadcosim.run(scenario, controller=cls, **kwargs)
    elapsed = time.perf_counter() - start
    assert isinstance(e.value.__cause__, quadcosim.StepTimeout)
    assert 0.2 <= elapsed < 5.0  # the limit plus the watchdog's poll (20 ms here) and a loaded machine's delays


def test_the_time_limit_does_not_touch_steps_within_it():
    """With a limit far above a step's time nothing is raised and the trajectory is that without one."""
    a = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD, step_timeout_s=5.0).trajectory
    b = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD).trajectory
    for name in STATE:
        assert np.array_equal(a[name], b[name]), name


def test_step_timeout_is_range_checked():
    with pytest.raises(quadcosim.ConfigError, match=r"controller\.step_timeout_s.*-1"):
        quadcosim.run(hover_scenario(step_timeout_s=-1), controller=AltitudePD)


# --- what step() sees -----------------------------------------------------------------------------------------


def test_obs_and_ref_mirror_the_node_observation_and_reference():
    """The same two objects every step, read-only arrays rewritten in place; t = n dt; the reference is the
    scenario's setpoint (z_des 10 from the schedule at 0 s, mode attitude); the observation is the sensed
    state (exact sensors here: the position is the state one plant tick earlier at most)."""
    seen = []

    class Probe(AltitudePD):
        def step(self, obs, ref, dt):
            seen.append((obs, ref, obs.p, float(obs.t), obs.p.copy(), obs.q.copy(), ref.mode, ref.p.copy(), dt,
                         obs.age, obs.p.flags.writeable))
            return super().step(obs, ref, dt)

    r = quadcosim.run({"simulation": {"duration_s": 2}, "controller": {"mode": "attitude", "z_des": 0},
                       "schedule": [{"at_s": 0, "set": {"z_des": 10.0}}]}, controller=Probe)
    assert len(seen) == 101  # steps at 0, 0.02, ..., 2.0 s
    obs0, ref0, p0 = seen[0][:3]
    tr = r.trajectory
    for n, (obs, ref, p, t, pc, q, mode, rp, dt, age, writeable) in enumerate(seen):
        assert obs is obs0 and ref is ref0 and p is p0
        assert t == n * 0.02 and dt == 0.02
        assert mode == "attitude" and list(rp) == [0.0, 0.0, 10.0]
        assert q[0] == 1.0 and not writeable
        assert 0.0 <= age <= 0.02
        # The position sample is that of the plant tick of this step or the one before.
        i = 2 * n
        assert any(pc[2] == tr["z"][j] for j in (i, i - 1) if j >= 0)
    with pytest.raises(ValueError):
        obs0.p[0] = 1.0
    assert "Observation(" in repr(obs0) and "Reference(" in repr(ref0)


# --- scenarios naming a class, Simulation, determinism -------------------------------------------------------


def write_controller_module(folder, name="my_controllers"):
    (folder / f"{name}.py").write_text(textwrap.dedent('''
        import math
        class AltitudePD:
            parameters = {"kp_z": dict(default=1.0, min=0.0, max=100.0), "kd_z": dict(default=1.4, min=0.0, max=100.0)}
            def __init__(self, vehicle):
                self.m, self.g, self.kt = vehicle["mass_kg"], vehicle["gravity_m_s2"], vehicle["kt_N_per_rad2_s2"]
            def step(self, obs, ref, dt):
                a = self.kp_z * float(ref.p[2] - obs.p[2]) - self.kd_z * float(obs.v[2])
                w = math.sqrt(max(self.m * (self.g + a), 0.0) / (4.0 * self.kt))
                return (w, w, w, w)
        '''))


def test_a_scenario_file_names_its_python_controller(tmp_path):
    """controller: {python: "my_controllers:AltitudePD"} imports the module from the scenario's folder; the
    run equals the same class given to run()."""
    write_controller_module(tmp_path)
    (tmp_path / "alt.yaml").write_text(textwrap.dedent('''
        simulation: {duration_s: 15}
        controller: {python: "my_controllers:AltitudePD", mode: attitude, z_des: 0, kp_z: 1.0}
        schedule: [{at_s: 0, set: {z_des: 10.0}}]
        '''))
    sc = quadcosim.load_scenario(tmp_path / "alt.yaml")
    assert sc.controller == "python"
    from_file = quadcosim.run(sc).trajectory
    given = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD).trajectory
    for name in STATE:
        assert np.array_equal(from_file[name], given[name]), name


def test_a_scenario_naming_a_missing_class_is_a_config_error(tmp_path):
    write_controller_module(tmp_path)
    for target, pattern in [("no_such_module:X", r"controller\.python.*ModuleNotFoundError"),
                            ("my_controllers:Nope", r"controller\.python.*has no 'Nope'"),
                            ("my_controllers", r"controller\.python.*expected module:Class"),
                            ("", r"controller\.python.*module:Class")]:
        (tmp_path / "bad.yaml").write_text(f'controller: {{type: python, python: "{target}"}}\n')
        with pytest.raises(quadcosim.ConfigError, match=pattern):
            quadcosim.load_scenario(tmp_path / "bad.yaml")
    (tmp_path / "bad.yaml").write_text('controller: {type: paper, python: "my_controllers:AltitudePD"}\n')
    with pytest.raises(quadcosim.ConfigError, match=r"controller\.type.*beside python"):
        quadcosim.load_scenario(tmp_path / "bad.yaml")


def test_simulation_steps_a_python_controller_as_the_run_flies_it():
    sc = quadcosim.load_scenario(ALTITUDE_STEP)
    result = quadcosim.run(sc, controller=AltitudePD)
    sim = quadcosim.Simulation(sc, controller=AltitudePD)
    for n in range(1, 200):
        sim.step()
        assert sim.state["p"][2] == result.trajectory["z"][2 * n]
    sim.reset()
    sim.step()
    assert sim.state["p"][2] == result.trajectory["z"][2]
    # A string keeps meaning a controller type.
    assert quadcosim.Simulation(sc, controller="se3").t == 0.0


def test_a_controller_cannot_step_its_own_simulation():
    holder = {}

    class Reentrant(AltitudePD):
        def step(self, obs, ref, dt):
            holder["sim"].t  # noqa: B018
            return super().step(obs, ref, dt)

    sim = quadcosim.Simulation(quadcosim.load_scenario(hover_scenario()), controller=Reentrant)
    holder["sim"] = sim
    with pytest.raises(quadcosim.ControllerError, match=r"called from inside its own step"):
        sim.step()


def test_runs_in_threads_serialise_on_the_gil_and_give_the_serial_numbers():
    """Four runs in four Python threads at once (each step takes the GIL; the simulation between steps
    runs without it): each gives exactly the trajectory of the same run alone."""
    alone = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD).trajectory
    results = [None] * 4

    def fly(i):
        results[i] = quadcosim.run(ALTITUDE_STEP, controller=AltitudePD).trajectory

    threads = [threading.Thread(target=fly, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        for name in STATE:
            assert np.array_equal(r[name], alone[name]), name


def test_a_string_keeps_meaning_a_controller_type(tmp_path):
    """controller="paper" on a scenario that names a Python class flies the paper controller (the class
    and its time limit go); the same scenario as written flies the class."""
    write_controller_module(tmp_path)
    (tmp_path / "s.yaml").write_text('simulation: {duration_s: 2}\n'
                                     'controller: {python: "my_controllers:AltitudePD", step_timeout_s: 1, z_des: 1}\n')
    assert quadcosim.load_scenario(tmp_path / "s.yaml").controller == "python"
    assert quadcosim.load_scenario(tmp_path / "s.yaml", controller="paper").controller == "paper"
    r = quadcosim.run(tmp_path / "s.yaml", controller="paper")
    assert r.trajectory["z"][-1] > 0.5


def test_two_runs_are_byte_identical(tmp_path):
    quadcosim.run(ALTITUDE_STEP, controller=AltitudePD, out=tmp_path / "a")
    quadcosim.run(ALTITUDE_STEP, controller=AltitudePD, out=tmp_path / "b")
    for name in ["trajectory.csv", "metrics.json", "metrics.txt"]:
        assert filecmp.cmp(tmp_path / "a" / name, tmp_path / "b" / name, shallow=False), name


def test_the_convenience_base_class():
    class Hover(quadcosim.Controller):
        parameters = {"scale": dict(default=1.0, min=0.5, max=2.0)}

        def step(self, obs, ref, dt):
            return [self.vehicle["hover_omega_rad_s"] * self.scale] * 4

    r = quadcosim.run(hover_scenario(duration_s=1.0), controller=Hover)
    assert np.max(np.abs(r.trajectory["z"] - 1.0)) < 1e-9
    with pytest.raises(quadcosim.ControllerError, match=r"NotImplementedError"):
        quadcosim.run(hover_scenario(duration_s=1.0), controller=quadcosim.Controller)


def test_a_run_records_the_python_class_and_its_module_hash(tmp_path):
    """The provenance of a run flown by a Python class: module:Class, the module's file and its SHA-256
    (hashed here from the file, independently), the parameter values; in RunResult, metrics.json and
    metadata.yaml alike, and scenario.yaml names the class."""
    import yaml
    r = quadcosim.run(hover_scenario(duration_s=0.1, kp_z=2.5), controller=AltitudePD, out=tmp_path / "run")
    c = r.provenance["controller"]
    assert c["type"] == "python" and c["override"] == "python"
    assert c["python"]["target"] == f"{__name__}:AltitudePD" and c["label"] == f"python {__name__}:AltitudePD"
    assert pathlib.Path(c["python"]["module_file"]).resolve() == pathlib.Path(__file__).resolve()
    assert c["python"]["sha256"] == hashlib.sha256(pathlib.Path(__file__).read_bytes()).hexdigest()
    assert c["parameters"]["kp_z"] == 2.5 and c["parameters"]["kd_z"] == 1.4
    assert json.loads((tmp_path / "run" / "metrics.json").read_text())["provenance"] == r.provenance
    assert yaml.safe_load((tmp_path / "run" / "metadata.yaml").read_text())["quadcosim_provenance"] == r.provenance
    assert yaml.safe_load((tmp_path / "run" / "scenario.yaml").read_text())["controller"]["python"] == \
        f"{__name__}:AltitudePD"


def test_another_class_does_not_inherit_the_scenarios_python_class_parameters(tmp_path):
    # A scenario flown by its own Python class with that class's gain; flown from Python by another
    # class (which declares no such gain), the gain goes with the file's class, as with the CLI's
    # --controller python:MODULE:CLASS. Before, the other class was handed 'k_own' and refused.
    (tmp_path / "own_controllers.py").write_text(textwrap.dedent("""
        class Own:
            parameters = {"k_own": dict(default=1.0, min=0.0, max=10.0, unit="1", description="a gain")}
            def step(self, obs, ref, dt):
                return [0.0] * 4
    """))
    scenario = tmp_path / "own.yaml"
    scenario.write_text(textwrap.dedent("""
        simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 0.1}
        controller: {python: "own_controllers:Own", k_own: 2.0}
    """))

    class Other:
        def step(self, obs, ref, dt):
            return [100.0] * 4

    result = quadcosim.run(str(scenario), controller=Other)
    assert result.trajectory["cmd1"][-1] == 100.0
