"""The envs' action levels: which command levels an env's actions may be at, and the range [lo, hi] each
normalised action a in [-1, 1] maps onto, c = lo + (a + 1) / 2 (hi - lo) (docs/python.md, "Action levels"
and "Gymnasium-style environments")."""

import math
from typing import Dict, Tuple

import numpy as np

ACTION_LEVELS = ("rotor_speeds", "rotor_thrusts", "ctbr", "ctatt", "cttm", "velocity", "acceleration")
# The half-ranges of the normalised actions that are not set by the vehicle (see quadcosim.envs).
ACTION_RANGES = {"rate_rad_s": 3.0, "angle_rad": 0.5, "speed_m_s": 2.0, "accel_m_s2": 4.0}


def action_ranges(level: str, vp: Dict[str, np.ndarray]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n, m) lower and upper ends of each action's command and the hover command, for each vehicle: m = 4,
    or the rotor count N at rotor_speeds (rotor_thrusts: four-rotor vehicles only)."""
    n = len(vp["mass_kg"])
    rotors = int(vp["rotor_count"][0]) if "rotor_count" in vp else 4
    w_lo, w_hi = vp["motor.omega_min_rad_s"], vp["motor.omega_max_rad_s"]
    kt = vp["kt_N_per_rad2_s2"]
    weight = vp["mass_kg"] * vp["gravity_m_s2"]
    zero, one = np.zeros(n), np.ones(n)
    cols = lambda *c: np.stack(c, axis=1)  # noqa: E731
    if level == "rotor_speeds":
        return cols(*[w_lo] * rotors), cols(*[w_hi] * rotors), cols(*[vp["hover_omega_rad_s"]] * rotors)
    if level == "rotor_thrusts":
        return cols(*[kt * w_lo**2] * 4), cols(*[kt * w_hi**2] * 4), cols(*[weight / 4] * 4)
    if level in ("velocity", "acceleration"):
        r = ACTION_RANGES["speed_m_s" if level == "velocity" else "accel_m_s2"] * one
        return cols(-r, -r, -r, -math.pi * one), cols(r, r, r, math.pi * one), cols(zero, zero, zero, zero)
    t_max = rotors * kt * w_hi**2
    if level == "ctbr":
        r = ACTION_RANGES["rate_rad_s"] * one
        half = (r, r, r)
    elif level == "ctatt":
        r = ACTION_RANGES["angle_rad"] * one
        half = (r, r, math.pi * one)
    else:  # cttm: what one rotor at full speed against its opposite stopped makes; yaw two rotors' drag
        xy = vp["arm_length_m"] * kt * w_hi**2
        half = (xy, xy, 2 * vp["km_Nm_per_rad2_s2"] * w_hi**2)
    return cols(zero, *[-h for h in half]), cols(t_max, *half), cols(weight, zero, zero, zero)
