"""Controllers written in Python for the tests of tests/python_node (docs/python.md).

AltitudePD: altitude hold with equal rotor speeds (level flight from a level start), thrust
m (g + kp_z (z_des - z) - kd_z vz), each rotor at sqrt(thrust / (4 k_t)).
Raising: AltitudePD that raises at the steps listed in its parameters.
Blocking: AltitudePD that sleeps in its step once.
"""
import math
import time


class AltitudePD:
    parameters = {
        "kp_z": dict(default=4.0, unit="1/s^2", min=0.0, max=100.0, description="altitude P gain"),
        "kd_z": dict(default=3.0, unit="1/s", min=0.0, max=100.0, description="altitude D gain"),
    }
    outputs = ("error.z",)

    def __init__(self, vehicle=None):
        v = vehicle or {}
        self.mass = float(v.get("mass_kg", 1.96))
        self.g = float(v.get("gravity_m_s2", 9.81))
        self.kt = float(v.get("kt_N_per_rad2_s2", 2.06e-7))
        self.step_index = -1  # the step being taken, numbered from 0 (t = index * dt in lockstep)

    def reset(self):
        self.step_index = -1

    def thrust(self, obs, ref):
        err = ref.p[2] - obs.p[2]
        return self.mass * (self.g + self.kp_z * err - self.kd_z * obs.v[2]), err

    def step(self, obs, ref, dt):
        self.step_index += 1
        t, err = self.thrust(obs, ref)
        w = math.sqrt(max(t, 0.0) / (4.0 * self.kt))
        return [w, w, w, w], [err]


class Raising(AltitudePD):
    """Raises ValueError at its steps first_bad .. first_bad + bad_count - 1 (numbered from 0)."""

    parameters = dict(AltitudePD.parameters)
    parameters["first_bad"] = dict(default=12.0, min=1.0, max=1e9, description="first step that raises")
    parameters["bad_count"] = dict(default=1e9, min=0.0, max=1e9, description="how many steps raise")

    def step(self, obs, ref, dt):
        result = super().step(obs, ref, dt)
        if self.first_bad <= self.step_index < self.first_bad + self.bad_count:
            raise ValueError("the test asks step %d to fail" % self.step_index)
        return result


class Blocking(AltitudePD):
    """Sleeps block_s in its step block_at (numbered from 0), then flies on."""

    parameters = dict(AltitudePD.parameters)
    parameters["block_at"] = dict(default=5.0, min=1.0, max=1e9, description="the step that sleeps")
    parameters["block_s"] = dict(default=10.0, unit="s", min=0.0, max=3600.0, description="how long it sleeps")

    def step(self, obs, ref, dt):
        result = super().step(obs, ref, dt)
        if self.step_index == int(self.block_at):
            time.sleep(self.block_s)
        return result
