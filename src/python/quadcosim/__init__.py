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

from ._quadcosim import ConfigError, ControllerError, Scenario, Simulation, StepTimeout
from . import _quadcosim

__all__ = ["ConfigError", "ControllerError", "StepTimeout", "Scenario", "Simulation", "RunResult", "load_scenario",
           "run"]

ScenarioLike = Union[Scenario, dict, str, "os.PathLike[str]"]


def load_scenario(source: Union[dict, str, "os.PathLike[str]"], controller: Optional[str] = None) -> Scenario:
    """Loads and validates a scenario.

    source: a scenario file (YAML, docs/scenarios.md), or a dict with the same keys and values as the
    file (nested dicts and lists; numbers, strings, bools, None; numpy scalars and arrays too).
    controller: a controller type replacing the scenario's controller.type (as `quadcosim run
    --controller`); the scenario's controller parameters are then checked against that type.

    Raises ConfigError (a ValueError) whose message names the file (or '<dict>'), the key and the
    value, e.g. "<dict>: simulation.plant_rate_hz: got 'fast', expected a number in [0.001, 1e+06]": the same
    checks and messages as the CLI.
    """
    ctype = controller or ""
    if isinstance(source, Scenario):
        return _quadcosim._with_controller(source, ctype)
    if isinstance(source, dict):
        return _quadcosim._load_scenario_dict(source, ctype)
    return _quadcosim._load_scenario_file(os.fspath(source), ctype)


@dataclass
class RunResult:
    """What quadcosim.run() returns.

    trajectory: dict of numpy float64 arrays keyed by the columns of trajectory.csv (t, x, y, z, vx,
        ..., qw, ..., roll, pitch, yaw, p, q, r, w1..w4, cmd1..cmd4, x_des..yaw_des, U1..U4, safety,
        watchdog, sat1..sat4, tilt_sat, att_err; docs/outputs.md), one value per plant tick: the same
        doubles as the file.
    figures: the figures and verdicts of metrics.json besides its header: "steps" (one dict per
        analysed step: channel, figures, criteria, passed, ...), and "hold", "saturation", "tracking"
        when the run has them.
    passed: the run's verdict (metrics.json "passed"; `quadcosim run` exits 0 exactly when it is True).
    metrics: the whole of metrics.json as a dict.
    table: metrics.txt, the table `quadcosim run` prints.
    messages: what the CLI would have printed besides the table (watchdog, injected faults, rejected
        commands, notes on an output folder), one line each.
    out: the output folder, or None.
    """

    trajectory: Dict[str, Any]
    figures: Dict[str, Any]
    passed: bool
    metrics: Dict[str, Any] = field(repr=False)
    table: str = field(repr=False)
    messages: str = field(repr=False)
    out: Optional[str] = None

    def __repr__(self) -> str:
        n = len(self.trajectory.get("t", []))
        return f"RunResult(passed={self.passed}, {n} ticks, figures={sorted(self.figures)}, out={self.out!r})"


# Keys of metrics.json that describe the run rather than judge it.
_HEADER_KEYS = {"scenario", "description", "passed", "controller", "schema", "version"}


def run(scenario: ScenarioLike, out: Optional[Union[str, "os.PathLike[str]"]] = None,
        controller: Any = None, force: bool = False, step_timeout_s: Optional[float] = None) -> RunResult:
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

    Ctrl-C raises KeyboardInterrupt within a few thousand plant ticks; out then holds what ran, as
    after an interrupted `quadcosim run`.

    Returns a RunResult (trajectory, figures, passed, ...). Raises ConfigError for a bad scenario,
    ValueError when out cannot be used (it holds other outputs), RuntimeError on an I/O error.
    """
    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if controller is not None or step_timeout_s is not None:
        sc = _quadcosim._with_any_controller(sc, controller, step_timeout_s)
    r = _quadcosim._run(sc, None if out is None else os.fspath(out), force)
    metrics = json.loads(r["metrics_json"])
    figures = {k: v for k, v in metrics.items() if k not in _HEADER_KEYS}
    return RunResult(trajectory=r["trajectory"], figures=figures, passed=bool(r["passed"]), metrics=metrics,
                     table=r["table"], messages=r["messages"], out=r["out"])
