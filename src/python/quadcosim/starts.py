"""Random initial states of the environments (their random_start=): hover-and-recover from anywhere near the target.

random_start is a dict of half-widths, each a number (every axis) or 3 numbers (x, y, z; roll, pitch, yaw):
  position_m    offset of the start from the position held [m, world], uniform in +-half-width per axis;
  attitude_rad  roll, pitch and yaw of the start relative to the scenario's initial attitude [rad], each
                uniform in +-half-width (composed yaw, then pitch, then roll: R = Rz(yaw) Ry(pitch) Rx(roll));
  velocity_m_s  initial velocity [m/s, world], uniform per axis;
  rate_rad_s    initial body rates [rad/s, body], uniform per axis.
A key left out is 0 (the scenario's value). The rotor speeds are the scenario's (hover speed with
`initial: hover: true`). Every episode draws its 12 numbers from its own Generator, in the order
position, attitude, velocity, rates (always all 12), so the same seed gives the same start.
"""

import math
from typing import Any, Dict, Optional

import numpy as np

__all__ = ["RECOVER_START", "check_start", "draw_start"]

# Hover-and-recover (examples/learn_hover.py): up to 1 m off on every axis, up to 30 deg in roll, pitch and
# yaw, moving at up to 0.2 m/s per axis and turning at up to 0.2 rad/s per axis.
RECOVER_START: Dict[str, Any] = {"position_m": 1.0, "attitude_rad": math.radians(30.0), "velocity_m_s": 0.2,
                                 "rate_rad_s": 0.2}

_KEYS = ("position_m", "attitude_rad", "velocity_m_s", "rate_rad_s")


def check_start(random_start: Optional[Dict[str, Any]]) -> Optional[np.ndarray]:
    """random_start as a (4, 3) array of half-widths (rows in the order of _KEYS), or None."""
    if random_start is None:
        return None
    if not isinstance(random_start, dict):
        raise ValueError(f"random_start: expected a dict with some of {list(_KEYS)}, got "
                         f"{type(random_start).__name__}")
    unknown = set(random_start) - set(_KEYS)
    if unknown:
        raise ValueError(f"random_start: unknown keys {sorted(unknown)}; expected some of {list(_KEYS)}")
    half = np.zeros((4, 3))
    for row, key in enumerate(_KEYS):
        if key not in random_start:
            continue
        try:
            h = np.broadcast_to(np.asarray(random_start[key], dtype=float), (3,))
        except (TypeError, ValueError):
            raise ValueError(f"random_start[{key!r}] = {random_start[key]!r}: expected a number or 3 numbers") \
                from None
        if not np.all(np.isfinite(h)) or np.any(h < 0):
            raise ValueError(f"random_start[{key!r}] = {random_start[key]!r}: expected finite half-widths >= 0")
        half[row] = h
    if half[1].max() > math.pi:
        raise ValueError(f"random_start['attitude_rad'] = {random_start['attitude_rad']!r}: expected at most pi")
    return half


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])


def euler_quat(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rz(yaw) Ry(pitch) Rx(roll) as a quaternion w, x, y, z."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
                     sy * cp * cr - cy * sp * sr])


def draw_start(rng: np.random.Generator, half: np.ndarray, p0: np.ndarray, q0: np.ndarray) -> Dict[str, np.ndarray]:
    """One start: p0 + offset, q0 * q(roll, pitch, yaw), v, w (12 uniform draws from rng)."""
    u = rng.uniform(-1.0, 1.0, size=(4, 3)) * half
    q = _quat_mul(np.asarray(q0, dtype=float), euler_quat(*u[1]))
    return {"p": np.asarray(p0, dtype=float) + u[0], "q": q / np.linalg.norm(q), "v": u[2], "w": u[3]}
