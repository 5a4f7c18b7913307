"""A Python controller that misbehaves at the step whose time reaches FAULTY_AT (environment) as
FAULTY_FAULT says: segv (reads address 0 through ctypes), abort (os.abort()), exit (os._exit(0)),
hang (time.sleep in C, past its step_timeout_s), raise (a ValueError: the controller's own error). Before that it holds altitude with equal rotor
speeds, so the run has a trajectory to keep. docs/reliability.md, "Foreign code"."""
import ctypes
import math
import os
import time


class Faulty:
    outputs = ("error.z",)

    def __init__(self, vehicle=None):
        v = vehicle or {}
        self.mass = float(v.get("mass_kg", 1.96))
        self.g = float(v.get("gravity_m_s2", 9.81))
        self.kt = float(v.get("kt_N_per_rad2_s2", 2.06e-7))
        self.fault = os.environ.get("FAULTY_FAULT", "")
        self.at = float(os.environ.get("FAULTY_AT", "1e9"))
        self.steps = 0

    def step(self, obs, ref, dt):
        t = self.steps * dt
        self.steps += 1
        if t >= self.at - 1e-9:
            print("faulty controller: %s at t = %g s" % (self.fault, t))
            if self.fault == "segv":
                ctypes.string_at(0)
            elif self.fault == "abort":
                os.abort()
            elif self.fault == "exit":
                os._exit(0)
            elif self.fault == "hang":
                time.sleep(1000)
            elif self.fault == "raise":
                raise ValueError("the test asks this step to fail")
        err = ref.p[2] - obs.p[2]
        thrust = self.mass * (self.g + 4.0 * err - 3.0 * obs.v[2])
        w = math.sqrt(max(thrust, 0.0) / (4.0 * self.kt))
        return [w, w, w, w], [err]
