"""The Python module against the CLI and against closed forms (run by tests/python/run_pytest.sh, CTest
python.pytest, with the module of the build tree on PYTHONPATH)."""

import filecmp
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import quadcosim

SOURCE = pathlib.Path(os.environ.get("QUADCOSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
QUADCOSIM = os.environ.get("QUADCOSIM_BIN", str(SOURCE / "build" / "bin" / "quadcosim"))
# Relative to SOURCE (the tests run there), so the CLI and the module see the same path text, which
# metrics.json records.
ALTITUDE_STEP = "scenarios/paper/altitude_step.yaml"

STATE_COLUMNS = {
    "p": ["x", "y", "z"],
    "v": ["vx", "vy", "vz"],
    "q": ["qw", "qx", "qy", "qz"],
    "w": ["p", "q", "r"],
    "omega": ["w1", "w2", "w3", "w4"],
}

# The paper's vehicle (docs/model.md): mass [kg] and gravity [m/s^2].
G = 9.81


@pytest.fixture(autouse=True)
def _in_source_dir(monkeypatch):
    monkeypatch.chdir(SOURCE)


def hover_scenario(z0=1.0, duration_s=10.0):
    """A trimmed hover at z0 (rotors at hover speed), the controller holding z0, no noise."""
    return {
        "name": "hover",
        "simulation": {"plant_rate_hz": 100, "controller_rate_hz": 50, "duration_s": duration_s},
        "initial": {"position_m": [0.0, 0.0, z0], "hover": True},
        "controller": {"mode": "attitude", "z_des": z0},
    }


# --- scenarios and their errors -----------------------------------------------------------------------


def test_load_scenario_from_file_and_dict():
    sc = quadcosim.load_scenario(ALTITUDE_STEP)
    assert sc.name == "altitude_step"
    assert sc.controller == "paper"
    assert sc.plant_period_s == pytest.approx(0.01)
    assert sc.control_period_s == pytest.approx(0.02)
    assert sc.duration_s == pytest.approx(15.0)
    d = quadcosim.load_scenario(hover_scenario())
    assert d.source == "<dict>" and d.name == "hover"
    assert isinstance(quadcosim.ConfigError("x"), ValueError)


def test_a_bad_key_is_named():
    bad = hover_scenario()
    bad["simulation"]["plant_rte_hz"] = 100
    with pytest.raises(quadcosim.ConfigError, match=r"plant_rte_hz") as e:
        quadcosim.load_scenario(bad)
    assert "<dict>" in str(e.value)


def test_a_bad_value_is_named_with_its_key():
    bad = hover_scenario()
    bad["simulation"]["plant_rate_hz"] = "fast"
    with pytest.raises(quadcosim.ConfigError) as e:
        quadcosim.load_scenario(bad)
    assert "simulation.plant_rate_hz" in str(e.value) and "fast" in str(e.value)


def test_the_same_error_as_the_file_gives(tmp_path):
    """A dict is checked exactly as the same keys written in a file: the same message but the source."""
    path = tmp_path / "bad.yaml"
    path.write_text("simulation:\n  duration_s: -3\n")
    with pytest.raises(quadcosim.ConfigError) as from_file:
        quadcosim.load_scenario(path)
    with pytest.raises(quadcosim.ConfigError) as from_dict:
        quadcosim.load_scenario({"simulation": {"duration_s": -3}})
    assert "duration_s" in str(from_file.value) and "-3" in str(from_file.value)
    assert str(from_file.value).replace(str(path), "<dict>") == str(from_dict.value)


def test_a_value_yaml_cannot_hold_is_refused():
    with pytest.raises(quadcosim.ConfigError, match=r"simulation\.duration_s.*object"):
        quadcosim.load_scenario({"simulation": {"duration_s": object()}})


# --- run: the same bytes as the CLI -----------------------------------------------------------------------


def test_run_writes_the_bytes_of_the_cli(tmp_path):
    cli, py = tmp_path / "cli", tmp_path / "py"
    done = subprocess.run([QUADCOSIM, "run", ALTITUDE_STEP, "--out", str(cli), "--no-plots"], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    result = quadcosim.run(ALTITUDE_STEP, out=py)
    for name in ["trajectory.csv", "metrics.txt", "scenario.yaml"]:
        assert filecmp.cmp(cli / name, py / name, shallow=False), name
    # metrics.json: the same judgement; the provenance differs only in the command line that ran it.
    import json
    m_cli, m_py = (json.loads((d / "metrics.json").read_text()) for d in (cli, py))
    p_cli, p_py = m_cli.pop("provenance"), m_py.pop("provenance")
    assert json.dumps(m_cli) == json.dumps(m_py)
    assert p_cli["command_line"][1:3] == ["run", ALTITUDE_STEP] and p_py["command_line"] != p_cli["command_line"]
    p_cli.pop("command_line"), p_py.pop("command_line")
    assert p_cli == p_py and p_py["controller"]["type"] == "paper" and p_py["transport"] == "inproc"
    assert result.provenance["controller"]["label"] == "paper"
    assert (py / "run.mcap").stat().st_size > 0 and (py / "metadata.yaml").exists()
    assert result.passed is True
    assert result.table == (cli / "metrics.txt").read_text()
    assert result.out == str(py)


def test_run_returns_the_trajectory_and_figures_of_its_files(tmp_path):
    result = quadcosim.run(ALTITUDE_STEP, out=tmp_path / "run")
    lines = (tmp_path / "run" / "trajectory.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert list(result.trajectory) == header
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    for i, name in enumerate(header):
        a = result.trajectory[name]
        assert a.dtype == np.float64 and a.shape == (len(lines) - 1,)
        assert np.array_equal(a, rows[:, i], equal_nan=True), name
    # 15 s at 100 Hz: ticks 0..1500.
    assert len(result.trajectory["t"]) == 1501
    import json
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert result.metrics == metrics
    assert result.passed == metrics["passed"]
    step = result.figures["steps"][0]
    assert step == metrics["steps"][0]
    assert step["channel"] == "z"


def test_judge_chooses_the_criteria_set_as_the_cli_does(tmp_path):
    # SE(3) on the paper's climb: no overshoot, so inside the spec (at most 25 %) and outside the
    # paper's 15-21 % band. judge= gives the verdict of `quadcosim run --judge`, the same bytes.
    spec = quadcosim.run(ALTITUDE_STEP, controller="se3")
    paper = quadcosim.run(ALTITUDE_STEP, controller="se3", judge="paper", out=tmp_path / "py")
    none = quadcosim.run(ALTITUDE_STEP, controller="se3", judge="none")
    assert (spec.passed, paper.passed, none.passed) == (True, False, None)
    assert (spec.judged, paper.judged, none.judged) == ("spec", "paper", "none")
    assert paper.metrics["judged"] == "paper" and none.metrics["passed"] is None
    assert spec.figures["steps"][0]["figures"] == none.figures["steps"][0]["figures"]
    assert spec.figures["steps"][0]["figures"]["overshoot_pct"] < 15
    cli = tmp_path / "cli"
    done = subprocess.run([QUADCOSIM, "run", ALTITUDE_STEP, "--controller", "se3", "--judge", "paper", "--out",
                           str(cli), "--no-plots"], capture_output=True, text=True)
    assert done.returncode == 1, done.stdout + done.stderr
    assert filecmp.cmp(cli / "metrics.txt", tmp_path / "py" / "metrics.txt", shallow=False)
    # metrics.json: the same judgement; only the provenance's command line tells the two apart.
    import json
    m_cli, m_py = (json.loads((d / "metrics.json").read_text()) for d in (cli, tmp_path / "py"))
    m_cli.pop("provenance"), m_py.pop("provenance")
    assert json.dumps(m_cli) == json.dumps(m_py)
    with pytest.raises(ValueError, match=r"judge: got 'strict', expected 'spec', 'paper' or 'none'"):
        quadcosim.run(ALTITUDE_STEP, judge="strict")


def test_run_without_out_leaves_nothing_and_gives_the_same_numbers(tmp_path):
    a = quadcosim.run(ALTITUDE_STEP)
    b = quadcosim.run(quadcosim.load_scenario(ALTITUDE_STEP), out=tmp_path / "b")
    assert a.out is None
    assert a.metrics == b.metrics
    for name in a.trajectory:
        assert np.array_equal(a.trajectory[name], b.trajectory[name], equal_nan=True), name


def test_run_refuses_a_folder_holding_other_outputs(tmp_path):
    quadcosim.run(ALTITUDE_STEP, out=tmp_path / "r")
    with pytest.raises(ValueError, match=str(tmp_path / "r")):
        quadcosim.run(ALTITUDE_STEP, out=tmp_path / "r")
    quadcosim.run(ALTITUDE_STEP, out=tmp_path / "r", force=True)


def interrupt_run(scenario, out):
    """quadcosim.run(scenario, out=out) with a SIGINT 0.2 s in: it must end with KeyboardInterrupt."""
    import _thread
    import threading
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            quadcosim.run(scenario, out=out)
    finally:
        timer.cancel()


def test_ctrl_c_ends_a_run_keeping_what_ran(tmp_path):
    """An hour simulated (360,001 ticks, seconds of wall time): a SIGINT 0.2 s in ends it promptly with
    KeyboardInterrupt, and trajectory.csv holds the ticks that ran, whole rows."""
    import time
    start = time.perf_counter()
    interrupt_run(hover_scenario(duration_s=3600.0), tmp_path / "long")
    lines = (tmp_path / "long" / "trajectory.csv").read_text().splitlines()
    assert 2 < len(lines) < 360_002
    assert all(len(line.split(",")) == len(lines[0].split(",")) for line in lines)
    assert time.perf_counter() - start < 30.0


# --- swarms -----------------------------------------------------------------------------------------------

GRID_TAKEOFF = "scenarios/swarm/grid_takeoff.yaml"


def test_a_swarm_flies_as_the_cli_flies_it(tmp_path):
    """9 vehicles of the shipped swarm from Python (1 thread) and from the CLI (2 threads): the same
    vehicles.csv and recorded trajectory, bit for bit; each vehicle's setpoint is the scenario's shifted
    by its grid cell (docs/scenarios.md: 3 columns of 2 m, z_des 5 m + (i mod 3) x 1 m)."""
    cli, py = tmp_path / "cli", tmp_path / "py"
    done = subprocess.run([QUADCOSIM, "run", GRID_TAKEOFF, "--vehicles", "9", "--threads", "2", "--out", str(cli),
                           "--no-plots"], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    result = quadcosim.run(GRID_TAKEOFF, out=py, vehicles=9, threads=1)
    assert isinstance(result, quadcosim.SwarmResult) and result.passed is True
    for name in ["vehicles.csv", "uav0000/trajectory.csv", "uav0000/metrics.txt", "uav0000/scenario.yaml"]:
        assert filecmp.cmp(cli / name, py / name, shallow=False), name
    assert not (py / "uav0063").exists()  # record_vehicles [0, 63]: 63 is beyond 9 vehicles
    v = result.vehicles
    assert v["namespace"] == [f"/uav{i:04d}" for i in range(9)]
    i = np.arange(9)
    assert np.array_equal(v["x_des_m"], (i % 3) * 2.0) and np.array_equal(v["y_des_m"], (i // 3) * 2.0)
    assert np.array_equal(v["z_des_m"], 5.0 + (i % 3) * 1.0)
    error = np.sqrt((v["x_m"] - v["x_des_m"]) ** 2 + (v["y_m"] - v["y_des_m"]) ** 2 + (v["z_m"] - v["z_des_m"]) ** 2)
    assert np.allclose(error, v["error_m"], rtol=1e-12, atol=0) and v["error_m"].max() < 0.01
    assert result.summary["vehicles"] == 9 and result.summary["final_error_m"]["max"] == v["error_m"].max()
    assert result.summary["recorded"][0]["passed"] is True and result.summary["threads"] == 1
    own = result.recorded["/uav0000"]
    assert own.passed is True and own.out == str(py / "uav0000") and own.figures["steps"][0]["channel"] == "z"
    assert own.trajectory["z"][-1] == v["z_m"][0] and own.trajectory["x"][-1] == v["x_m"][0]
    assert own.table == (cli / "uav0000" / "metrics.txt").read_text()
    assert result.provenance["controller"]["label"] == "paper" and "swarm: 9 vehicles" in result.messages


def test_a_swarm_judged_none_and_bad_sizes(tmp_path):
    none = quadcosim.run(GRID_TAKEOFF, vehicles=2, judge="none")
    assert none.passed is None and none.recorded["/uav0000"].passed is None and none.out is None
    one = quadcosim.run(hover_scenario(duration_s=1.0), vehicles=2)  # no swarm: section: records none
    assert list(one.vehicles["index"]) == [0.0, 1.0] and one.recorded == {} and one.passed is True
    for bad in (0, -3, 1.5, True):
        with pytest.raises(ValueError, match=r"vehicles: got .*, expected a whole number >= 1"):
            quadcosim.run(GRID_TAKEOFF, vehicles=bad)
    with pytest.raises(ValueError, match=r"threads: got 0"):
        quadcosim.run(GRID_TAKEOFF, threads=0)


def test_ctrl_c_ends_a_swarm_keeping_what_ran(tmp_path):
    """4 vehicles for an hour: a SIGINT 0.2 s in ends it with KeyboardInterrupt after the block being
    flown; the recorded vehicle's trajectory.csv holds whole rows, and no summary claims an end."""
    long = dict(hover_scenario(duration_s=3600.0), swarm={"vehicles": 4, "record_vehicles": [1]})
    interrupt_run(long, tmp_path / "long")
    lines = (tmp_path / "long" / "uav0001" / "trajectory.csv").read_text().splitlines()
    assert 2 < len(lines) < 360_002
    assert all(len(line.split(",")) == len(lines[0].split(",")) for line in lines)
    assert not (tmp_path / "long" / "summary.json").exists()


# --- stepping -------------------------------------------------------------------------------------------


def test_hover_holds_its_altitude():
    """From a trimmed hover the vehicle is in equilibrium: thrust k * omega_h^2 equals m g up to the
    rounding of a few floating-point operations (relative error <= 16 eps, eps = 2.2e-16), a vertical
    acceleration bias |a| <= 16 eps g. Even uncorrected, such a bias moves the vehicle at most
    1/2 |a| T^2 in T seconds (1.7e-12 m over 10 s); the altitude loop only holds it closer."""
    sim = quadcosim.Simulation(quadcosim.load_scenario(hover_scenario(z0=1.0)))
    T = 10.0
    bias = 16 * np.finfo(float).eps * G
    tolerance = 0.5 * bias * T**2
    steps = round(T / sim.dt)
    worst = 0.0
    for _ in range(steps):
        sim.step()
        p = sim.state["p"]
        worst = max(worst, abs(p[2] - 1.0), abs(p[0]), abs(p[1]))
    assert sim.t == pytest.approx(T)
    assert worst <= tolerance, f"strayed {worst} m from the hover point (bound {tolerance} m)"


def test_stepping_equals_the_run_bit_for_bit():
    """After n control periods the state is the run's trajectory row at tick n * divider, bit for bit
    (the same lockstep loop and schedule; the CSV holds shortest round-trip text of the same doubles)."""
    sc = quadcosim.load_scenario(ALTITUDE_STEP)
    result = quadcosim.run(sc)
    sim = quadcosim.Simulation(sc)
    divider = round(sc.control_period_s / sc.plant_period_s)
    checked = 0
    for n in range(1, 301):  # 6 s: the rise, the overshoot (peak near 2.5 s) and the settling
        sim.step()
        if n % 25 and n != 300:
            continue
        row = n * divider
        assert sim.tick == row
        assert sim.t == result.trajectory["t"][row]
        state = sim.state
        for key, columns in STATE_COLUMNS.items():
            expected = np.array([result.trajectory[c][row] for c in columns])
            assert np.array_equal(state[key], expected), (n, key, state[key], expected)
        checked += 1
    assert checked == 12
    # The step happened: z left the ground (a closed-loop flight, not a vehicle at rest).
    assert sim.state["p"][2] > 5.0


def test_reset_with_the_same_seed_repeats_the_numbers():
    sc = quadcosim.load_scenario("scenarios/realism/roll_step_noisy_imu.yaml")
    sim = quadcosim.Simulation(sc, seed=11)

    def fly():
        out = []
        for _ in range(60):
            sim.step()
            out.append(np.concatenate([sim.state["p"], sim.state["q"], sim.sensors["imu"]["w"]]))
        return np.array(out)

    first = fly()
    sim.reset()
    assert sim.t == 0.0 and sim.seed == 11
    again = fly()
    assert np.array_equal(first, again)
    sim.reset(seed=12)
    other = fly()
    assert not np.array_equal(first, other)  # the noise is the seed's
    sim.reset(seed=11)
    assert np.array_equal(first, fly())


def test_rotor_commands_bypass_the_controller():
    sim = quadcosim.Simulation(quadcosim.load_scenario(hover_scenario()))
    sim.step()
    hover = sim.command.copy()
    assert np.all(hover > 0)
    cmd = np.array([hover[0] + 20, hover[1] - 20, hover[2] + 20, hover[3] - 20])
    sim.step(omega_cmd=cmd)
    assert np.array_equal(sim.command, cmd)
    # Zero rotor speed for a period: the plant latches it, the vehicle starts to fall.
    v0 = sim.state["v"][2]
    sim.step(omega_cmd=np.zeros(4))
    assert np.array_equal(sim.command, np.zeros(4))
    sim.step(omega_cmd=np.zeros(4))
    assert sim.state["v"][2] < v0
    sim.step()  # the controller flies again
    assert not np.array_equal(sim.command, np.zeros(4))
    with pytest.raises(ValueError, match="omega_cmd"):
        sim.step(omega_cmd=np.zeros(3))


def test_setpoints_and_sensors():
    sim = quadcosim.Simulation(quadcosim.load_scenario(hover_scenario(z0=1.0)))
    assert sim.sensors == {}
    assert sim.setpoint["z"] == 1.0 and sim.setpoint["mode"] == "attitude"
    sim.set_setpoint(z=2.0)
    assert sim.setpoint["z"] == 2.0
    for _ in range(int(round(8.0 / sim.dt))):
        sim.step()
    assert abs(sim.state["p"][2] - 2.0) < 0.05  # the paper's PD settles within 2 % in about 8 s
    s = sim.sensors
    # Noise-free sensors: the pose the plant published at the last tick of the period.
    assert s["pose"]["t"] == pytest.approx(sim.t - sim.dt / 2)
    assert abs(s["pose"]["p"][2] - sim.state["p"][2]) < 0.01
    assert s["imu"]["a"][2] == pytest.approx(G, abs=0.5)  # specific force of a hover: g upwards
    with pytest.raises(TypeError, match="altitude"):
        sim.set_setpoint(altitude=3.0)
    with pytest.raises(ValueError, match="mode"):
        sim.set_setpoint(mode="sideways")


def test_the_extra_sensors_in_sensors():
    """scenarios/realism/all_sensors.yaml: the magnetometer, barometer and GNSS reach sim.sensors in SI
    units, each agreeing with the true state through formulas written here (field elements, metres per
    degree on a sphere, the ISA's altitude-to-pressure law inverted by the module), within its noise."""
    sim = quadcosim.Simulation("scenarios/realism/all_sensors.yaml")
    for _ in range(50):
        sim.step()
    s = sim.sensors
    assert not s["gnss"]["fix"] and math.isnan(s["gnss"]["latitude_deg"])  # fix_after_s 1.0, 0.1 s latency
    for _ in range(50):
        sim.step()
    s, x = sim.sensors, sim.state
    # Magnetometer: R^T B_W + hard iron, B_W from F = 48 uT, I = 63.5 deg, D = 3 deg (ENU).
    F, I, D = 48e-6, math.radians(63.5), math.radians(3.0)
    B = np.array([F * math.cos(I) * math.sin(D), F * math.cos(I) * math.cos(D), -F * math.sin(I)])
    w, qx, qy, qz = x["q"]
    R = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)],
                  [2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)],
                  [2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)]])
    expected = R.T @ B + np.array([2.0e-6, -1.5e-6, 0.8e-6])
    assert np.abs(s["magnetometer"]["field"] - expected).max() < 2.5e-6, (s["magnetometer"], expected)
    # Barometer: the pressure altitude of 488 m + z, off by its bias (turn-on sigma 20 Pa ~ 1.7 m).
    assert abs(s["barometer"]["altitude"] - (488.0 + x["p"][2])) < 10.0, s["barometer"]
    assert 90000 < s["barometer"]["pressure"] < 100000
    # GNSS: 0.1 s old, sigma 0.8 m horizontal, 1.5 m vertical; a degree of latitude is ~111.2 km.
    g = s["gnss"]
    assert g["fix"] and g["t"] == pytest.approx(1.9)
    metres_per_deg = math.pi / 180 * 6371000.0
    assert abs((g["latitude_deg"] - 47.397742) * metres_per_deg - x["p"][1]) < 5.0, g
    east = (g["longitude_deg"] - 8.545594) * metres_per_deg * math.cos(math.radians(47.397742))
    assert abs(east - x["p"][0]) < 5.0, (east, x["p"])
    assert abs(g["altitude_m"] - (488.0 + x["p"][2])) < 8.0, g
    assert np.abs(g["v"] - x["v"]).max() < 0.5
    # The paper's scenarios have none of them.
    paper = quadcosim.Simulation(ALTITUDE_STEP)
    paper.step()
    assert sorted(paper.sensors) == ["imu", "pose", "velocity"]


def test_help_teaches_the_api():
    text = quadcosim.Simulation.__doc__ + "".join(
        getattr(quadcosim.Simulation, n).__doc__ or "" for n in ["step", "set_setpoint", "reset", "state", "sensors"])
    for word in ["omega_cmd", "seed", "set_setpoint", "rotor speeds", "world frame"]:
        assert word in text
    assert "ConfigError" in quadcosim.load_scenario.__doc__
    assert "trajectory.csv" in quadcosim.run.__doc__


def test_run_result_outputs_are_the_controllers_own_figures():
    # The paper controller declares its errors; RunResult.outputs holds them by name, as trajectory.csv's
    # out.<name> columns. At t = 0 the vehicle is on the ground and z_des is 10 m: e_z = 10 exactly.
    result = quadcosim.run(ALTITUDE_STEP)
    assert list(result.outputs) == ["error.z", "error.roll", "error.pitch", "error.yaw"]
    e_z = result.outputs["error.z"]
    assert e_z.shape == result.trajectory["t"].shape
    assert np.array_equal(e_z, result.trajectory["out.error.z"], equal_nan=True)
    assert e_z[0] == 10.0
    assert abs(e_z[-1]) < 0.1  # settled by 15 s
    assert np.all(result.outputs["error.roll"] == 0.0)  # level flight: nothing disturbs roll


def test_a_vehicle_preset_from_a_dict_with_an_override():
    """`vehicle: {preset: NAME}` starts from a ready vehicle (docs/model.md); other keys override it."""
    sc = quadcosim.load_scenario({"vehicle": {"preset": "crazyflie2", "mass_kg": 0.03}, "controller": {"type": "se3"}})
    assert sc.vehicle["mass_kg"] == 0.03
    assert sc.vehicle["Ixy_kg_m2"] == 0.830806e-6  # Förster's identified tensor
    assert sc.vehicle["layout"] == "x"
    with pytest.raises(quadcosim.ConfigError, match="preset"):
        quadcosim.load_scenario({"vehicle": {"preset": "crazyfly"}})
