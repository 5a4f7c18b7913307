"""The extra sensors (magnetometer, barometer, GNSS; docs/sensors.md, "In the controller") as the foreign
controllers observe them: a Python controller's obs.magnetometer, obs.barometer, obs.gnss against what
Simulation.sensors recorded at the same ticks, in process and in a child process of its own (the CLI), in
a Batch; and an FMU controller's inputs of the same names (tests/fmi/sensor_echo) against the Python
controller's observation. Run by tests/python/run_pytest.sh (CTest python.pytest)."""

import math
import os
import pathlib
import subprocess

import numpy as np
import pytest
import yaml

import quadcosim

SOURCE = pathlib.Path(os.environ.get("QUADCOSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
QUADCOSIM = os.environ.get("QUADCOSIM_BIN", str(SOURCE / "build" / "bin" / "quadcosim"))
ALL_SENSORS = "scenarios/realism/all_sensors.yaml"
ALTITUDE_STEP = "scenarios/paper/altitude_step.yaml"
OMEGA = 4830.0  # near the default vehicle's hover speed: the vehicle sinks slowly, the same in every run

# What the echo controllers report of their observation, in the registry's column order: the plant
# FMU's output names (and the FMU controller's inputs) with "seen." in front.
COLUMNS = ["magnetometer.field[1]", "magnetometer.field[2]", "magnetometer.field[3]", "barometer.pressure",
           "barometer.altitude", "gnss.fix", "gnss.latitude_deg", "gnss.longitude_deg", "gnss.altitude_m",
           "gnss.v[1]", "gnss.v[2]", "gnss.v[3]"]
ECHO_MODULE = '''
class SensorEcho:
    """Commands a constant speed; reports every column of the extra sensors it observed."""

    parameters = {"omega": dict(default=0.0, min=0.0, max=10000.0)}
    outputs = tuple("seen." + c for c in %r)

    def step(self, obs, ref, dt):
        m, b, g = obs.magnetometer, obs.barometer, obs.gnss
        seen = [*m.field, b.pressure, b.altitude, 1.0 if g.fix else 0.0, g.latitude_deg, g.longitude_deg,
                g.altitude_m, *g.v]
        return (self.omega,) * 4, seen
''' % (COLUMNS,)


@pytest.fixture(autouse=True)
def _in_source_dir(monkeypatch):
    monkeypatch.chdir(SOURCE)


def all_sensors(duration_s=3.0, **controller):
    """scenarios/realism/all_sensors.yaml with `controller` as its controller section (no schedule, no
    analysis: they are the paper controller's), flown for duration_s."""
    d = yaml.safe_load((SOURCE / ALL_SENSORS).read_text())
    for key in ("controller", "schedule", "analysis"):
        d.pop(key)
    d["simulation"]["duration_s"] = duration_s
    d["controller"] = controller
    return d


def recorder():
    """A controller class that commands a constant speed and keeps, per step, a copy of the extra sensors
    it observed (a list the class closes over: the run flies a deep copy of the object), and the objects
    themselves (to check they are reused); the class and the two lists."""
    seen, objects = [], []

    class Recorder:
        def step(self, obs, ref, dt):
            m, b, g = obs.magnetometer, obs.barometer, obs.gnss
            objects.append((m, b, g, m.field, g.v))
            seen.append({
                "magnetometer": {"t": m.t, "field": m.field.copy()},
                "barometer": {"t": b.t, "pressure": b.pressure, "altitude": b.altitude},
                "gnss": {"t": g.t, "fix": g.fix, "latitude_deg": g.latitude_deg, "longitude_deg": g.longitude_deg,
                         "altitude_m": g.altitude_m, "v": g.v.copy()},
            })
            return (OMEGA,) * 4

    return Recorder, seen, objects


def flat(obs):
    """One step's observation of the extra sensors as numbers (t None as NaN)."""
    m, b, g = obs.magnetometer, obs.barometer, obs.gnss
    t = [math.nan if x.t is None else x.t for x in (m, b, g)]
    return [t[0], *m.field, t[1], b.pressure, b.altitude, t[2], float(g.fix), g.latitude_deg, g.longitude_deg,
            g.altitude_m, *g.v]


BATCH_SEEN = {}  # id of the controller object -> its flat() per step


class BatchRecorder:
    """At module level: a Batch imports its vehicles' controllers by module:Class."""

    def step(self, obs, ref, dt):
        BATCH_SEEN.setdefault(id(self), []).append(flat(obs))
        return (OMEGA,) * 4


def same(a, b):
    """Bit for bit, NaN equal to NaN."""
    return np.array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float), equal_nan=True)


def stamp_s(ns):
    """A stamp [ns] in seconds as a message header gives it: sec + nanosec * 1e-9."""
    return (ns // 1_000_000_000) + (ns % 1_000_000_000) * 1e-9


def test_obs_holds_the_samples_simulation_sensors_recorded_at_the_same_ticks():
    """With the controller at the plant rate (100 Hz), the step at tick n sees the newest sample of each
    sensor published by tick n, which Simulation.sensors shows after that step: the magnetometer's of tick
    n, the barometer's (50 Hz) of the last even tick, the GNSS's (10 Hz) of the last tenth tick. The
    numbers cross bit for bit except latitude and longitude, which cross the wire in degrees and come
    back in radians (within 1 ulp of the plant's)."""
    cls, seen, _ = recorder()
    d = all_sensors()
    d["simulation"]["controller_rate_hz"] = 100
    sim = quadcosim.Simulation(d, controller=cls)
    fixes = 0
    for n in range(200):
        sim.step()
        after = sim.sensors
        assert len(seen) == n + 1
        for kind in ("magnetometer", "barometer", "gnss"):
            o, s = seen[n][kind], after[kind]
            assert o["t"] == s["t"], (n, kind)
            assert set(o) == set(s), kind
            for col, value in s.items():
                if col in ("latitude_deg", "longitude_deg") and not math.isnan(value):
                    assert o[col] == pytest.approx(value, rel=2.3e-16, abs=0), (n, kind, col)
                else:
                    assert same(o[col], value), (n, kind, col, o[col], value)
                    assert type(o[col]) is type(value), (kind, col)
        fixes += bool(after["gnss"]["fix"])
    # The stamps: the magnetometer every tick, the barometer every other, the GNSS every tenth.
    assert [s["magnetometer"]["t"] for s in seen] == [stamp_s(10_000_000 * n) for n in range(200)]
    assert [s["barometer"]["t"] for s in seen] == [stamp_s(20_000_000 * (n // 2)) for n in range(200)]
    assert [s["gnss"]["t"] for s in seen] == [stamp_s(100_000_000 * (n // 10)) for n in range(200)]
    # A fix from the sample published at 1.1 s (it measures the truth of 1.0 s, fix_after_s).
    assert fixes == 200 - 110


def test_obs_sensor_readings_at_a_slower_controller():
    """At the scenario's 50 Hz controller the step at tick 2n sees the magnetometer's sample of tick 2n
    (one of two skipped), the barometer's every step, the GNSS's every fifth step; no fix before the
    sample measuring 1 s; the readings near what the scenario's site and the state say; the same objects
    every step, arrays read-only."""
    cls, seen, objects = recorder()
    sim = quadcosim.Simulation(all_sensors(), controller=cls)
    for _ in range(100):
        sim.step()
    assert [s["magnetometer"]["t"] for s in seen] == [stamp_s(20_000_000 * n) for n in range(100)]
    assert [s["barometer"]["t"] for s in seen] == [stamp_s(20_000_000 * n) for n in range(100)]
    assert [s["gnss"]["t"] for s in seen] == [stamp_s(100_000_000 * (n // 5)) for n in range(100)]
    # Every sensor publishes at tick 0, so the first step has a sample of each (t 0, not None).
    assert all(seen[0][k]["t"] == 0.0 for k in ("magnetometer", "barometer", "gnss"))
    # No fix before fix_after_s = 1 s of measured time (the numbers NaN, fix False), a fix after.
    g = seen[54]["gnss"]
    assert g["fix"] is False and math.isnan(g["latitude_deg"]) and np.isnan(g["v"]).all()
    g = seen[55]["gnss"]
    assert g["fix"] is True and abs(g["altitude_m"] - (488.0 + 10.0)) < 10.0
    assert abs(g["latitude_deg"] - 47.397742) < 1e-4 and abs(g["longitude_deg"] - 8.545594) < 1e-4
    # The barometer's pressure altitude near 488 m + 10 m; the magnetometer's field near 48 uT.
    assert abs(seen[99]["barometer"]["altitude"] - 498.0) < 10.0
    assert 40e-6 < np.linalg.norm(seen[99]["magnetometer"]["field"]) < 56e-6
    # The same objects every step; the arrays read-only, rewritten in place.
    first = objects[0]
    for these in objects:
        assert all(a is b for a, b in zip(these, first))
    with pytest.raises(ValueError):
        first[3][0] = 1.0
    assert isinstance(seen[99]["barometer"]["altitude"], float)
    assert isinstance(first[2], quadcosim.SensorReading)
    assert "SensorReading(" in repr(first[2]) and "latitude_deg=" in repr(first[2])


def test_a_vehicle_without_the_sensors_observes_none():
    seen = []

    class Probe:
        def step(self, obs, ref, dt):
            seen.append((obs.magnetometer, obs.barometer, obs.gnss))
            return (OMEGA,) * 4

    sim = quadcosim.Simulation(ALTITUDE_STEP, controller=Probe)
    sim.step()
    assert seen == [(None, None, None)]
    # Only the barometer.
    d = all_sensors()
    d["sensors"] = {"barometer": {"rate_hz": 50}}
    seen.clear()
    sim = quadcosim.Simulation(d, controller=Probe)
    sim.step()
    m, b, g = seen[0]
    assert m is None and g is None and b is not None and b.t == 0.0


def write_echo(folder, duration_s=3.0):
    """The echo controller's module and a scenario naming it in `folder`; the scenario's path."""
    (folder / "echo_controllers.py").write_text(ECHO_MODULE)
    d = all_sensors(duration_s, python="echo_controllers:SensorEcho", omega=OMEGA)
    (folder / "echo.yaml").write_text(yaml.safe_dump(d))
    return folder / "echo.yaml"


def seen_columns(trajectory):
    return np.array([trajectory["out.seen." + c] for c in COLUMNS])


def test_an_isolated_python_controller_sees_the_same_numbers(tmp_path):
    """The CLI flies the Python controller in a child process of its own (the Observation copied byte for
    byte); its trajectory.csv is the bytes of the same run in process (quadcosim.run), the columns of
    what it observed included."""
    scenario = write_echo(tmp_path)
    cli, py = tmp_path / "cli", tmp_path / "py"
    done = subprocess.run([QUADCOSIM, "run", str(scenario), "--out", str(cli), "--no-plots"], capture_output=True,
                          text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    result = quadcosim.run(scenario, out=py)
    assert (cli / "trajectory.csv").read_bytes() == (py / "trajectory.csv").read_bytes()
    # The echoed columns are the observation's: not all NaN (the GNSS had a fix after 1 s).
    seen = seen_columns(result.trajectory)
    assert np.isfinite(seen[:5]).all() and np.isfinite(seen[:, -1]).all()
    assert seen[5, 0] == 0.0 and seen[5, -1] == 1.0


def test_a_batch_python_controller_observes_the_sensors_as_a_simulation():
    """quadcosim.Batch with a Python controller: each vehicle observes what a single Simulation with its
    seed observes, bit for bit."""
    sc = quadcosim.load_scenario(all_sensors(), controller=BatchRecorder)
    singles = {}
    for seed in (11, 12):
        BATCH_SEEN.clear()
        sim = quadcosim.Simulation(sc, seed=seed)
        for _ in range(60):
            sim.step()
        (singles[seed],) = BATCH_SEEN.values()
    BATCH_SEEN.clear()
    batch = quadcosim.Batch(sc, 2, seeds=[11, 12], threads=2)
    for _ in range(60):
        batch.step()
    assert len(BATCH_SEEN) == 2
    # Each vehicle's record is the one single run's with the same first step (the seeds' noise differs).
    records = list(BATCH_SEEN.values())
    assert not same(singles[11][0], singles[12][0])
    for record in records:
        seed = 11 if same(record[0], singles[11][0]) else 12
        assert len(record) == len(singles[seed])
        for n, (a, b) in enumerate(zip(record, singles[seed])):
            assert same(a, b), (seed, n, a, b)
    assert {11 if same(r[0], singles[11][0]) else 12 for r in records} == {11, 12}


def test_an_fmu_controller_gets_the_observations_readings_as_its_inputs(tmp_path):
    """tests/fmi/sensor_echo: an FMU with inputs named like the plant FMU's sensor outputs echoes them; it
    gets exactly what the Python controller observes in the same run (the same commands, so the same
    plant and samples)."""
    fmu = pathlib.Path(QUADCOSIM).resolve().parents[1] / "tests" / "fmi" / "sensor_echo.fmu"
    if not fmu.exists():
        pytest.skip(f"the test FMU was not built ({fmu})")
    scenario = write_echo(tmp_path)
    python = quadcosim.run(scenario).trajectory
    assert np.isfinite(seen_columns(python)[:, -1]).all()  # every column a number by the end (a fix)
    for in_process in (True, False):
        controller = {"fmu": str(fmu), "omega": OMEGA}
        if in_process:
            controller["in_process"] = True
        from_fmu = quadcosim.run(all_sensors(**controller)).trajectory
        assert same(seen_columns(from_fmu), seen_columns(python)), in_process
        for key in ("x", "y", "z"):
            assert same(from_fmu[key], python[key])
    # Without the GNSS on, the FMU is refused at load, naming its input and the key that turns it on.
    d = all_sensors(fmu=str(fmu))
    del d["sensors"]["gnss"]
    with pytest.raises(quadcosim.ConfigError, match=r"controller\.fmu: sensor_echo\.fmu has the input 'gnss\.fix', "
                                                    r"but the vehicle carries no gnss: turn it on with the scenario "
                                                    r"key sensors\.gnss"):
        quadcosim.load_scenario(d)
