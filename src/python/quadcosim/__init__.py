"""quadcosim from Python: scenarios, runs and stepping of quadcosim's quadrotor co-simulation.

    import quadcosim
    result = quadcosim.run("scenarios/paper/altitude_step.yaml")
    result.passed                      # the verdict of `quadcosim run` (metrics.json "passed")
    result.trajectory["z"]             # numpy float64, one value per plant tick
    result.figures["steps"][0]         # the step figures, as in metrics.json

    sim = quadcosim.Simulation(quadcosim.load_scenario("scenarios/paper/hover.yaml"))
    sim.step(); sim.state["p"]

load_scenario() validates a scenario (a file or a dict with the keys of a file, docs/scenarios.md) and
raises ConfigError naming the key and the value on a mistake; run() flies it in process exactly as
`quadcosim run` does and writes the same files; Simulation steps it one control period at a time.
See docs/python.md.
"""

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Union

import numpy  # noqa: F401  (the arrays the module returns; fail here, clearly, without it)

from ._quadcosim import (ConfigError, ControllerError, Observation, Reference, Scenario, SensorReading, Simulation,
                         StepTimeout)
from . import _quadcosim
from .batch import Batch  # noqa: E402  (N vehicles stepped together; docs/python.md)
from . import envs  # noqa: E402  (Gymnasium-style environments: HoverEnv, TrackingEnv, VectorHoverEnv, ...)

__all__ = ["ConfigError", "Controller", "ControllerError", "Observation", "Reference", "SensorReading", "StepTimeout",
           "Scenario", "SwarmResult", "Simulation", "RunResult", "load_scenario", "run"]

ScenarioLike = Union[Scenario, dict, str, "os.PathLike[str]"]


def load_scenario(source: Union[Scenario, dict, str, "os.PathLike[str]"], controller: Any = None,
                  step_timeout_s: Optional[float] = None) -> Scenario:
    """Loads and validates a scenario.

    source: a scenario file (YAML, docs/scenarios.md), or a dict with the same keys and values as the
    file (nested dicts and lists; numbers, strings, bools, None; numpy scalars and arrays too), or a
    Scenario (to change its controller).
    controller: a controller type replacing the scenario's controller.type (a str, as `quadcosim run
    --controller`), or a controller written in Python (an instance or a class, see Controller); the
    scenario's controller parameters and schedule are then checked against that controller's.
    step_timeout_s: the per-step time limit of a Python controller [s] (0: none), as the scenario key
    controller.step_timeout_s.

    Raises ConfigError (a ValueError) whose message names the file (or '<dict>'), the key and the
    value, e.g. "<dict>: simulation.plant_rate_hz: got 'fast', expected a number in [0.001, 1e+06]": the same
    checks and messages as the CLI.
    """
    if not isinstance(source, (Scenario, dict)):
        source = os.fspath(source)
    return _quadcosim._load(source, controller, step_timeout_s)


@dataclass
class RunResult:
    """What quadcosim.run() returns.

    trajectory: dict of numpy float64 arrays keyed by the columns of trajectory.csv (t, x, y, z, vx,
        ..., qw, ..., roll, pitch, yaw, p, q, r, w1..w4, cmd1..cmd4, x_des..yaw_des, U1..U4, safety,
        watchdog, sat1..sat4, tilt_sat, att_err, then out.<name> for each figure the controller declares;
        docs/outputs.md), one value per plant tick: the same doubles as the file.
    figures: the figures and verdicts of metrics.json besides its header: "steps" (one dict per
        analysed step: channel, figures, criteria, passed, ...), and "hold", "saturation", "tracking"
        when the run has them.
    passed: the run's verdict on the criteria set judged (metrics.json "passed"; `quadcosim run` exits 0
        exactly when it is not False): True or False, None with judge="none" (figures only).
    metrics: the whole of metrics.json as a dict.
    table: metrics.txt, the table `quadcosim run` prints.
    messages: what the CLI would have printed besides the table (watchdog, injected faults, rejected
        commands, notes on an output folder), one line each.
    out: the output folder, or None.
    provenance: what flew and how (metrics.json "provenance", docs/outputs.md): controller (label, type,
        parameter values; for a Python class module:Class, its module file and SHA-256), transport,
        command line, quadcosim version and git commit, host, scenario file and its SHA-256.
    judged: the criteria set the run was judged against: "spec", "paper" or "none" (run's judge=).
    outputs (property): the controller's own figures, name -> array (the out.<name> columns of trajectory).
    """

    trajectory: Dict[str, Any]
    figures: Dict[str, Any]
    passed: Optional[bool]
    metrics: Dict[str, Any] = field(repr=False)
    table: str = field(repr=False)
    messages: str = field(repr=False)
    out: Optional[str] = None
    provenance: Dict[str, Any] = field(default_factory=dict, repr=False)
    judged: str = "spec"

    @property
    def outputs(self) -> Dict[str, Any]:
        """The figures the controller declares (its `outputs`), by name: trajectory's out.<name> columns."""
        return {k[len("out."):]: v for k, v in self.trajectory.items() if k.startswith("out.")}

    def __repr__(self) -> str:
        n = len(self.trajectory.get("t", []))
        return f"RunResult(passed={self.passed}, {n} ticks, figures={sorted(self.figures)}, out={self.out!r})"


@dataclass
class SwarmResult:
    """What quadcosim.run() returns for a swarm (a scenario with a swarm: section, or vehicles=N).

    vehicles: vehicles.csv as a dict of numpy arrays (index, x_m, y_m, z_m, x_des_m, y_des_m, z_des_m,
        error_m, safety, commands_rejected: one value per vehicle) and "namespace" (a list of str).
    recorded: namespace -> RunResult for each vehicle of swarm.record_vehicles ("/uav0000": its
        trajectory, figures, passed, metrics, table), the same doubles as its <ns>/trajectory.csv.
    passed: no recorded vehicle failed a judged criterion (`quadcosim run` exits 0 exactly when it is not
        False); None with judge="none".
    summary: summary.json as a dict (layout, final_error_m spread, vehicles_in_safety, wall_s, ...,
        "recorded" verdicts, "provenance").
    messages, out, provenance, judged: as RunResult's.
    """

    vehicles: Dict[str, Any]
    recorded: Dict[str, RunResult]
    passed: Optional[bool]
    summary: Dict[str, Any] = field(repr=False)
    messages: str = field(repr=False)
    out: Optional[str] = None
    provenance: Dict[str, Any] = field(default_factory=dict, repr=False)
    judged: str = "spec"

    def __repr__(self) -> str:
        n = len(self.vehicles.get("index", []))
        return (f"SwarmResult(passed={self.passed}, {n} vehicles, recorded={sorted(self.recorded)}, "
                f"out={self.out!r})")


def _vehicles_columns(text: str) -> Dict[str, Any]:
    """vehicles.csv as columns: numpy float64 arrays, the namespace as a list of str."""
    lines = text.splitlines()
    names = lines[0].split(",")
    rows = [line.split(",") for line in lines[1:]]
    return {name: ([r[i] for r in rows] if name == "namespace" else numpy.array([float(r[i]) for r in rows]))
            for i, name in enumerate(names)}


class Controller:
    """A convenience base class for controllers written in Python (any object with step() flies).

        class AltitudePD(quadcosim.Controller):
            parameters = {"kp_z": dict(default=1.0, unit="1/s^2", min=0.0, max=100.0,
                                       description="vertical acceleration per metre of altitude error")}
            outputs = ("error.z",)

            def step(self, obs, ref, dt):
                e = ref.p[2] - obs.p[2]
                ...
                return omega, (e,)

    parameters: name -> dict(default=, unit="", min=-inf, max=inf, description="") (numbers). They are
        the keys of a scenario's controller: section (range-checked), can be changed by its schedule: and
        are the controller node's ROS 2 parameters. The current value of each is an attribute of the
        object (self.kp_z), set before the first step and after each accepted change.
    outputs: names of the figures step() returns besides the rotor speeds.
    step_timeout_s: the default per-step time limit [s] (0: none); a scenario's
        controller.step_timeout_s or run(..., step_timeout_s=) overrides it.

    __init__(vehicle) receives the vehicle as a dict (Scenario.vehicle: mass_kg, gravity_m_s2,
    kt_N_per_rad2_s2, hover_omega_rad_s, mixer_inverse, ...) when quadcosim instantiates the class;
    here it is kept as self.vehicle. reset() clears internal state (integrators); set_parameters(changes)
    may refuse a change by raising ValueError (nothing changes then). step(obs, ref, dt) returns 4 rotor
    speeds [rad/s], or (omega, outputs). See docs/python.md, "Write a controller in Python".
    """

    parameters: Dict[str, Any] = {}
    outputs: tuple = ()

    def __init__(self, vehicle: Optional[Dict[str, Any]] = None):
        self.vehicle = vehicle

    def reset(self) -> None:
        """Clears internal state (integrators, filters), as after a restart."""

    def set_parameters(self, changes: Dict[str, float]) -> None:
        """Called with {name: new value} (already range-checked) before the attributes change; raise
        ValueError to refuse."""

    def step(self, obs, ref, dt: float):
        """One control period of dt seconds: return 4 rotor speeds [rad/s] (or (omega, outputs))."""
        raise NotImplementedError(f"{type(self).__name__}.step")


# Keys of metrics.json that describe the run rather than judge it.
_HEADER_KEYS = {"scenario", "scenario_file", "description", "passed", "controller", "schema", "version", "judged",
                "judged_criteria", "judged_note", "provenance"}
# What run(judge=...) takes, as `quadcosim run --judge`.
_JUDGE_SETS = ("spec", "paper", "none")


def run(scenario: ScenarioLike, out: Optional[Union[str, "os.PathLike[str]"]] = None,
        controller: Any = None, force: bool = False, step_timeout_s: Optional[float] = None,
        judge: str = "spec", vehicles: Optional[int] = None,
        threads: Optional[int] = None) -> Union[RunResult, SwarmResult]:
    """Runs a scenario in process, as `quadcosim run SCENARIO --out OUT --no-plots` does.

    scenario: a Scenario, a scenario file or a dict (see load_scenario).
    out: when given, the output folder (new or empty, created when missing; with force=True a previous
        command's outputs there are replaced, as with --force): trajectory.csv, run.mcap,
        metadata.yaml, metrics.json, metrics.txt and scenario.yaml, the same bytes as the CLI writes
        (the PNG plots and report.html are not made: `quadcosim plot OUT` makes them). Without out the
        run is recorded in a temporary folder that is removed.
    controller: a controller type replacing the scenario's (a str, as --controller), or a controller
        written in Python: an instance or a class with step(obs, ref, dt) (see Controller and
        docs/python.md). The run flies a copy.deepcopy of the configured object (the object passed is
        not stepped). A failing Python controller raises ControllerError naming the step.
    step_timeout_s: the per-step time limit of a Python controller [s] (None keeps the scenario's or
        the class's, default 0: no limit); a step that runs longer is stopped with StepTimeout and the
        run raises ControllerError.
    judge: the criteria set the run is judged against, as `quadcosim run --judge`: "spec" (the
        scenario's specification: bounds a good controller must meet), "paper" (the paper controller's
        measured response bands) or "none" (figures only: every figure computed, passed is None).
        Every figure and both sets' bands are in metrics.json whatever is judged.

    vehicles: a swarm of N vehicles on a grid, as `quadcosim run --vehicles N` (None: the scenario's
        swarm: section, or one vehicle when it has none). threads: the swarm's worker threads, as
        --threads (None: swarm.threads, 2). A swarm returns a SwarmResult and writes what the CLI's
        in-process swarm writes: vehicles.csv, summary.json, and trajectory.csv, metrics.json,
        metrics.txt and scenario.yaml of each recorded vehicle in <out>/<namespace>.

    Ctrl-C raises KeyboardInterrupt within a few thousand plant ticks (a swarm: after the block of 100
    ticks being flown); out then holds what ran, as after an interrupted `quadcosim run`.

    Returns a RunResult (trajectory, figures, passed, ...), or a SwarmResult for a swarm. Raises
    ConfigError for a bad scenario, ValueError when out cannot be used (it holds other outputs) or for
    a bad judge, vehicles or threads, RuntimeError on an I/O error.
    """
    if judge not in _JUDGE_SETS:
        raise ValueError(f"judge: got {judge!r}, expected 'spec', 'paper' or 'none'")
    for name, value in (("vehicles", vehicles), ("threads", threads)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
            raise ValueError(f"{name}: got {value!r}, expected a whole number >= 1 (or None)")
    sc = load_scenario(scenario, controller, step_timeout_s)
    r = _quadcosim._run(sc, None if out is None else os.fspath(out), force, judge, vehicles or 0, threads or 0)
    if r["swarm"]:
        summary = json.loads(r["summary_json"])
        recorded = {}
        for v in r["recorded"]:
            folder = None if r["out"] is None else os.path.join(r["out"], v["namespace"][1:])
            metrics = json.loads(v["metrics_json"])
            recorded[v["namespace"]] = _run_result(v["trajectory"], metrics, metrics["passed"], v["table"], "",
                                                   folder, r["judged"])
        return SwarmResult(vehicles=_vehicles_columns(r["vehicles_csv"]), recorded=recorded, passed=r["passed"],
                           summary=summary, messages=r["messages"], out=r["out"], judged=r["judged"],
                           provenance=summary.get("provenance", {}))
    return _run_result(r["trajectory"], json.loads(r["metrics_json"]), r["passed"], r["table"], r["messages"],
                       r["out"], r["judged"])


def _run_result(trajectory: Dict[str, Any], metrics: Dict[str, Any], passed: Optional[bool], table: str,
                messages: str, out: Optional[str], judged: str) -> RunResult:
    """A RunResult from a recorded vehicle's trajectory columns and its metrics.json."""
    figures = {k: v for k, v in metrics.items() if k not in _HEADER_KEYS}
    return RunResult(trajectory=trajectory, figures=figures, passed=passed, metrics=metrics, table=table,
                     messages=messages, out=out, judged=judged, provenance=metrics.get("provenance", {}))
