"""quadcosim.Batch: N vehicles of one scenario stepped together, state and sensors as (N, k) numpy arrays.

    batch = quadcosim.Batch("scenarios/paper/altitude_step.yaml", 1000,
                            vehicles={"mass_kg": rng.uniform(0.9, 1.1, 1000) * 0.468})
    batch.set_setpoints(z=np.linspace(1, 3, 1000))
    batch.step()                              # every controller flies one control period
    batch.step(omega_cmd=np.full((1000, 4), 450.0))   # or rotor speeds [rad/s], controllers bypassed

    ctbr = quadcosim.Batch("scenarios/paper/altitude_step.yaml", 1000, plant_only=True, action="ctbr")
    ctbr.step(np.tile([19.2276, 0.0, 0.0, 0.1], (1000, 1)))   # thrust [N], body rates [rad/s]
    batch.p, batch.q, batch.sensors["imu"]["a"]        # (1000, 3), (1000, 4), (1000, 3)

Each vehicle flies the scenario with its own seed and vehicle parameters: vehicle i gives exactly
(bit for bit) the numbers of quadcosim.Simulation(scenario with vehicle i's keys, seed=seeds[i]). A
vehicle has no bus (nobody could subscribe to it): its plant and its controller node's core are
stepped directly, in the nodes' order, the vehicles in one contiguous array; a scenario with message
faults or an FMU plant makes each vehicle a whole Simulation instead. With plant_only=True (rotor
commands from Python, as in reinforcement learning) each vehicle is its plant alone, with the same
numbers. See docs/python.md.
"""

import math
import numbers
import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from ._quadcosim import ConfigError, Scenario
from . import _quadcosim

__all__ = ["Batch"]


def _yaml_text(value: Any, where: str) -> str:
    """`value` (dicts, lists, numbers, strings, bools; numpy scalars and arrays) as YAML flow text, floats
    in Python's shortest round-trip form (as load_scenario writes a dict's numbers)."""
    if isinstance(value, dict):
        items = []
        for k, v in value.items():
            if not isinstance(k, str):
                raise ConfigError(f"{where}: key {k!r} is not a string")
            items.append(f"{_quote(k)}: {_yaml_text(v, f'{where}.{k}')}")
        return "{" + ", ".join(items) + "}"
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml_text(v, f"{where}[{i}]") for i, v in enumerate(value)) + "]"
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return _quote(value)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        d = float(value)
        if math.isnan(d):
            return ".nan"
        if math.isinf(d):
            return ".inf" if d > 0 else "-.inf"
        return repr(d)
    raise ConfigError(f"{where}: got {value!r} of type {type(value).__name__}, expected a number, string, bool, "
                      "list or dict")


def _quote(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _nest(flat: Dict[str, Any]) -> Dict[str, Any]:
    """{"motor.tau_up_s": 0.05, "mass_kg": 1} -> {"motor": {"tau_up_s": 0.05}, "mass_kg": 1}. A key with a
    dot names a key of a section (motor, aero) as in model::vehicle_parameters()."""
    out: Dict[str, Any] = {}
    for key, value in flat.items():
        if not isinstance(key, str):
            raise ConfigError(f"Batch: vehicles: key {key!r} is not a string")
        parts = key.split(".")
        d = out
        for p in parts[:-1]:
            d = d.setdefault(p, {})
            if not isinstance(d, dict):
                raise ConfigError(f"Batch: vehicles: {key} given both as a section and as a value")
        if isinstance(value, dict):
            d.setdefault(parts[-1], {}).update(_nest(value))
        else:
            d[parts[-1]] = value
    return out


def _flatten(d: Dict[str, Any], prefix: str = "") -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for k, v in d.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flatten(v, name + "."))
        else:
            out[name] = v
    return out


def _vehicle_keys(vehicles: Any, n: int, what: str = "vehicles") -> List[str]:
    """Each vehicle's keys of the scenario's `vehicle:` section as YAML text ("" for none)."""
    if vehicles is None:
        return [""] * n
    if isinstance(vehicles, dict):
        # A dict of arrays: one value (or one row, for 3-vectors) per vehicle; a scalar is everyone's.
        columns = _flatten(vehicles)
        per_vehicle: List[Dict[str, Any]] = [{} for _ in range(n)]
        for key, values in columns.items():
            a = np.asarray(values) if not isinstance(values, str) else np.asarray(values, dtype=object)
            if a.ndim == 0:
                for i in range(n):
                    per_vehicle[i][key] = a.item()
                continue
            if a.shape[0] != n:
                raise ConfigError(f"Batch: {what}[{key!r}]: expected {n} values (one per vehicle), got an array of "
                                  f"shape {a.shape}")
            for i in range(n):
                per_vehicle[i][key] = a[i].tolist() if isinstance(a[i], np.ndarray) else a[i]
        return [_yaml_text(_nest(v), f"vehicle {i}") if v else "" for i, v in enumerate(per_vehicle)]
    if isinstance(vehicles, (str, bytes)) or not isinstance(vehicles, Sequence):
        raise ConfigError(f"Batch: {what}: expected a list of {n} dicts of vehicle keys or a dict of arrays, got "
                          f"{type(vehicles).__name__}")
    if len(vehicles) != n:
        raise ConfigError(f"Batch: {what}: {len(vehicles)} dicts for {n} vehicles")
    keys = []
    for i, v in enumerate(vehicles):
        if v is None or (isinstance(v, dict) and not v):
            keys.append("")
        elif isinstance(v, dict):
            keys.append(_yaml_text(_nest(v), f"vehicle {i}"))
        else:
            raise ConfigError(f"Batch: {what}[{i}]: expected a dict of vehicle keys, got {type(v).__name__}")
    return keys


def _seeds(seeds: Any, n: int, what: str) -> List[int]:
    a = np.asarray(seeds)
    if a.ndim == 0:
        a = np.full(n, a)
    if a.shape != (n,):
        raise ValueError(f"Batch.{what}: seeds: expected {n} seeds, got an array of shape {a.shape}")
    out = []
    for i, s in enumerate(a.tolist()):
        if not isinstance(s, int) or isinstance(s, bool) or not 0 <= s < 2**64:
            raise ValueError(f"Batch.{what}: seeds[{i}] = {s!r}: expected an integer in [0, 2^64)")
        out.append(s)
    return out


_STATE_PARTS = (("p", 3), ("v", 3), ("q", 4), ("w", 3))


def _start_states(states: Any, m: int) -> np.ndarray:
    """Batch.reset's states as the (m, 13) rows _Batch.reset takes: p, v, q, w; NaN where not given."""
    if not isinstance(states, dict):
        raise ValueError(f"Batch.reset: states: expected a dict of arrays p, v, q, w, got {type(states).__name__}")
    unknown = set(states) - {k for k, _ in _STATE_PARTS}
    if unknown:
        raise ValueError(f"Batch.reset: states: unknown keys {sorted(unknown)}; expected some of p, v, q, w")
    rows = np.full((m, 13), np.nan)
    col = 0
    for key, width in _STATE_PARTS:
        if key in states:
            try:
                a = np.asarray(states[key], dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"Batch.reset: states[{key!r}]: expected numbers") from None
            if a.shape == (width,):
                a = np.broadcast_to(a, (m, width))
            if a.shape != (m, width):
                raise ValueError(f"Batch.reset: states[{key!r}]: expected shape ({m}, {width}), got {a.shape}")
            if not np.all(np.isfinite(a)):
                i = int(np.argwhere(~np.isfinite(a))[0][0])
                raise ValueError(f"Batch.reset: states[{key!r}][{i}] = {a[i].tolist()}: expected finite numbers")
            if key == "q":
                norm = np.linalg.norm(a, axis=1)
                if np.any(norm < 1e-9):
                    i = int(np.argmax(norm < 1e-9))
                    raise ValueError(f"Batch.reset: states['q'][{i}] = {a[i].tolist()}: not a rotation (norm 0)")
                # Normalised, but a unit one (to 1e-12) is taken as it is: the same bits fly.
                off = np.abs(norm - 1.0) > 1e-12
                a = np.where(off[:, None], a / norm[:, None], a)
            rows[:, col:col + width] = a
        col += width
    return rows


def _default_threads() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


class Batch:
    """N vehicles of one scenario, stepped together one control period at a time.

    scenario: a Scenario, a scenario file or a dict (see load_scenario).
    n: the number of vehicles.
    seeds: one seed per vehicle (an int: the same for all); None: the scenario's seed + i for vehicle i.
        A vehicle's seed drives its sensor noise, wind and injected message faults, as
        Simulation(seed=).
    vehicles: each vehicle's own parameters, keys of the scenario's `vehicle:` section (docs/model.md):
        a list of n dicts ({"mass_kg": 0.5, "motor": {"tau_up_s": 0.03}}; None or {} keeps the
        scenario's), or a dict of arrays of length n ({"mass_kg": masses, "motor.tau_up_s": taus};
        an (n, 3) array for a 3-vector such as aero.linear_drag_N_s_m; a scalar applies to all).
        Each vehicle's scenario is validated as the file with those keys would be; a bad key or value
        raises ConfigError naming the vehicle, the key and the value.
    controller_vehicle: "own" (default): each vehicle's controller is designed for its own parameters,
        as a scenario file with those keys would be (vehicle i then equals that Simulation bit for
        bit); "nominal": every controller is designed for the scenario's vehicle, which the vehicles
        only approximate (as the runs of a sweep; what robustness checks and domain randomisation want).
    threads: worker threads that step the vehicles (default: the CPUs this process may use); the
        numbers do not depend on it.
    plant_only: no controllers: every step() gives omega_cmd (the rotor speeds come from Python, as
        in reinforcement learning). Each vehicle is then only its plant: the same numbers as a
        vehicle with its controller flying the same commands (bit for bit: state, command, sensors
        with their noise), with less memory per step (docs/python.md). set_setpoints raises;
        setpoints and reference give the scenario's. Scenarios with injected message faults or
        external dynamics (an FMU) are refused (ConfigError).
    action: the command level of step()'s commands (docs/python.md, "Action levels"): "rotor_speeds"
        (default: omega_i [rad/s]), "rotor_thrusts" (T_i [N]), "ctbr" (collective thrust [N], body
        rates p, q, r [rad/s] FLU), "ctatt" (thrust [N], roll, pitch, yaw [rad] Z-Y-X), "cttm" (thrust
        [N], body torques [N m]), "velocity" (v_x, v_y, v_z [m/s] world ENU, yaw [rad]),
        "acceleration" (a_x, a_y, a_z [m/s^2] world, gravity excluded, yaw [rad]). Above rotor
        speeds, each plant's inner loops (control/inner_loops.hpp, docs/controllers.md) turn the
        command into rotor speeds on every plant tick from the vehicle's true state. An unknown name
        raises ValueError listing the levels.

    Arrays come back as copies: (n, 3) p, v [m, m/s world], w [rad/s body]; (n, 4) q (w, x, y, z body
    -> world), omega, command [rad/s]; (n,) t [s], tick.
    """

    def __init__(self, scenario: Union[Scenario, dict, str, "os.PathLike[str]"], n: int, seeds: Any = None,
                 vehicles: Any = None, threads: Optional[int] = None, controller_vehicle: str = "own",
                 plant_only: bool = False, action: str = "rotor_speeds", _sections: Optional[Dict[str, Any]] = None):
        from . import load_scenario  # the package's loader (a file, a dict or a Scenario)

        sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise ValueError(f"Batch: n = {n!r}: expected a number of vehicles >= 1")
        n = int(n)
        if seeds is None:
            seeds = [(sc.seed + i) % 2**64 for i in range(n)]
        threads = _default_threads() if threads is None else threads
        if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or threads < 1:
            raise ValueError(f"Batch: threads = {threads!r}: expected an integer >= 1")
        yaml = sc.yaml()
        if _sections:
            # Top-level sections replaced (a TrackingEnv's trajectory): merged into the document.
            yaml = _quadcosim._replace_sections(yaml, _yaml_text(_sections, "sections"))
        self.scenario = sc
        if controller_vehicle not in ("own", "nominal"):
            raise ValueError(f"Batch: controller_vehicle = {controller_vehicle!r}: expected 'own' or 'nominal'")
        self._b = _quadcosim._Batch(yaml, sc.source, _vehicle_keys(vehicles, n), _seeds(seeds, n, "__init__"),
                                    int(threads), controller_vehicle == "nominal", bool(plant_only), str(action))
        self.n = n

    # --- stepping ----------------------------------------------------------------------------------

    def step(self, command: Optional[np.ndarray] = None, periods: int = 1, *,
             omega_cmd: Optional[np.ndarray] = None) -> None:
        """Advances every vehicle one control period (dt seconds, ticks_per_step plant ticks).

        command: None (each vehicle's controller flies) or an (n, 4) array of commands at the batch's
        action level (rotor speeds [rad/s] by default, then (n, N): one per rotor of the vehicle, N = 6
        for a hexarotor; see `action`) for this period, the controllers
        bypassed (as Simulation.step(omega_cmd=)). A wrong shape or a value that is not finite raises
        ValueError naming the row and the field, and steps nothing; so does None in a plant_only batch.
        omega_cmd: the same, by its older name (rotor-speed batches only).
        periods: control periods to advance in this call (the command, if given, held over all of
        them). The numbers equal `periods` calls of step(); each vehicle runs them back to back while
        its data is in the CPU's cache, which is faster for many vehicles (docs/performance.md).
        """
        if omega_cmd is not None:
            if command is not None:
                raise ValueError("Batch.step: give command or omega_cmd, not both")
            if self.action != "rotor_speeds":
                raise ValueError(f"Batch.step: omega_cmd: this batch's action is {self.action!r}: give its commands "
                                 "as command=")
            command = omega_cmd
        self._b.step(command, int(periods))

    def reset(self, indices: Optional[Sequence[int]] = None, seeds: Any = None, vehicles: Any = None,
              states: Optional[Dict[str, Any]] = None) -> None:
        """Back to t = 0 for the vehicles `indices` (None: all), with their scenario's initial state and
        setpoints.

        seeds: new seeds for those vehicles (an int, or one per index; None keeps each one's, so the
        numbers repeat). vehicles: new vehicle keys for them (as for the constructor, one per index;
        None keeps each one's). states: where they start instead of the scenario's initial state, a
        dict of arrays with one row per index (keys as Batch.state's): p (m, 3) [m, world], v (m, 3)
        [m/s, world], q (m, 4) w, x, y, z body -> world (normalised unless its norm is 1 to 1e-12; a
        zero or non-finite one raises), w (m, 3) [rad/s, body]; a key left out keeps the scenario's
        value (position and yaw of its `initial:` section, at rest). The rotor speeds are the scenario's (hover speed with
        `initial: hover: true`, else stopped). Everything is checked before anything is reset.
        """
        idx = None if indices is None else [int(i) for i in np.atleast_1d(np.asarray(indices)).tolist()]
        m = self.n if idx is None else len(idx)
        s = None if seeds is None else _seeds(seeds, m, "reset")
        k = None if vehicles is None else _vehicle_keys(vehicles, m)
        x = None if states is None else _start_states(states, m)
        self._b.reset(idx, s, k, x)

    def set_setpoints(self, indices: Optional[Sequence[int]] = None, **values: Any) -> None:
        """Sets the controller nodes' setpoints by keyword, from the next step on: x, y, z [m], roll,
        pitch, yaw [rad] (a number for all, or an array with one value per vehicle) and mode
        ('attitude' or 'position', or a list). indices: only these vehicles (values then one per index).
        A value out of range or not finite raises ValueError naming the vehicle; then no setpoint changes.
        """
        idx = None if indices is None else [int(i) for i in np.atleast_1d(np.asarray(indices)).tolist()]
        self._b.set_setpoints(idx, **values)

    # --- what the vehicles are doing -----------------------------------------------------------------

    @property
    def p(self) -> np.ndarray:
        """(n, 3) positions, world frame [m]."""
        return self._b.get("p")

    @property
    def v(self) -> np.ndarray:
        """(n, 3) velocities, world frame [m/s]."""
        return self._b.get("v")

    @property
    def q(self) -> np.ndarray:
        """(n, 4) attitudes body -> world as w, x, y, z."""
        return self._b.get("q")

    @property
    def R(self) -> np.ndarray:
        """(n, 9) rotation matrices body -> world of q, row by row (R[0,0], R[0,1], ..., R[2,2])."""
        return self._b.get("R")

    @property
    def w(self) -> np.ndarray:
        """(n, 3) body angular velocities [rad/s]."""
        return self._b.get("w")

    @property
    def omega(self) -> np.ndarray:
        """(n, N) rotor speeds [rad/s], one column per rotor (N = 4 for a quadrotor)."""
        return self._b.get("omega")

    @property
    def command(self) -> np.ndarray:
        """(n, N) the rotor commands [rad/s] the plants latched in their last tick, one column per rotor."""
        return self._b.get("command")

    @property
    def state(self) -> Dict[str, np.ndarray]:
        """The true states as a dict of arrays p, v, q, w, omega (as Simulation.state, one row each)."""
        return {k: self._b.get(k) for k in ("p", "v", "q", "w", "omega")}

    @property
    def sensors(self) -> Dict[str, Dict[str, np.ndarray]]:
        """The latest sensor messages each plant published (what its controller sees, after noise,
        latency and injected faults), as Simulation.sensors with one row per vehicle: pose: t (n,),
        p (n, 3), q (n, 4); velocity: t, v (world), w (body); imu: t, q, w, a (n, 3). NaN before a
        vehicle's first step.

        With the scenario's extra sensors (docs/sensors.md), as the plant published them, with the
        names of Simulation.sensors: magnetometer: t, field (n, 3) body [T]; barometer: t,
        pressure [Pa], altitude [m] (its ISA pressure altitude); gnss: t, fix (1.0 with a fix, 0.0
        without), latitude_deg, longitude_deg, altitude_m (NaN without a fix), v (n, 3) ENU [m/s]."""
        d = {
            "pose": {k: self._b.get("pose." + k) for k in ("t", "p", "q")},
            "velocity": {k: self._b.get("velocity." + k) for k in ("t", "v", "w")},
            "imu": {k: self._b.get("imu." + k) for k in ("t", "q", "w", "a")},
        }
        for sensor, columns in self._b.sensor_columns().items():
            d[sensor] = {k: self._b.get(sensor + "." + k) for k in ["t"] + list(columns)}
        return d

    @property
    def setpoints(self) -> Dict[str, Any]:
        """The controller nodes' setpoints: mode (a list), x, y, z, roll, pitch, yaw ((n,) arrays)."""
        return self._b.setpoints()

    @property
    def reference(self) -> Dict[str, np.ndarray]:
        """What each vehicle is asked to reach at its time t: the scenario's trajectory (p (n, 3),
        v (n, 3), yaw (n,)) when it has one, else the setpoint (v zero)."""
        return self._b.reference()

    @property
    def tracks_trajectory(self) -> bool:
        """True when the scenario has a `trajectory:` (reference follows it)."""
        return self._b.tracks_trajectory()

    @property
    def vehicle_params(self) -> Dict[str, np.ndarray]:
        """Each vehicle's numeric parameters by their YAML path (mass_kg, kt_N_per_rad2_s2,
        motor.omega_max_rad_s, aero.linear_drag_N_s_m.x, ...), rotor_count N and hover_omega_rad_s =
        sqrt(m g / (N k_t)),
        (n,) arrays."""
        return self._b.vehicle_params()

    @property
    def t(self) -> np.ndarray:
        """(n,) simulated time of each vehicle [s] (vehicles reset alone restart at 0)."""
        return self._b.get("t")

    @property
    def tick(self) -> np.ndarray:
        """(n,) int64 plant tick of each vehicle's state."""
        return self._b.ticks()

    @property
    def seeds(self) -> np.ndarray:
        """(n,) uint64 seeds in use."""
        return self._b.seeds()

    @property
    def dt(self) -> float:
        """The control period [s]: what one step() advances."""
        return self._b.dt()

    @property
    def ticks_per_step(self) -> int:
        """Plant ticks per step() (the scenario's controller divider)."""
        return self._b.ticks_per_step()

    @property
    def plant_period_s(self) -> float:
        return self._b.plant_period_s()

    @property
    def plant_only(self) -> bool:
        """True when the batch has no controllers (Batch(plant_only=True)): step() needs omega_cmd."""
        return self._b.plant_only()

    @property
    def action(self) -> str:
        """The command level of step()'s commands ("rotor_speeds", "ctbr", ...)."""
        return self._b.action()

    @property
    def threads(self) -> int:
        """Worker threads in use (at most n)."""
        return self._b.threads()

    def __len__(self) -> int:
        return self.n

    def __repr__(self) -> str:
        lean = " plant_only" if self.plant_only else ""
        action = "" if self.action == "rotor_speeds" else f" action={self.action}"
        return f"<quadcosim.Batch '{self.scenario.name}' n={self.n} threads={self.threads}{lean}{action}>"
