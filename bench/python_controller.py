#!/usr/bin/env python3
"""Speed of a controller written in Python, flown in process: the paper's altitude step (100 Hz plant,
50 Hz controller, 15 s: 750 controller calls, 1500 plant ticks), stepped with quadcosim.Simulation.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_controller.py [repetitions]

Flies, interleaved, per repetition (each a fresh Simulation stepped through the whole scenario):
  cpp_paper      the scenario's own C++ controller (the reference: the same loop without Python calls)
  py_constant    a Python controller returning constant hover speeds (what the adapter costs)
  py_pd          a scalar Python PD on altitude (kp, kd, gravity feedforward; math.sqrt)
and quadcosim.run() of the scenario with py_pd (records trajectory.csv, run.mcap, metrics into a
temporary folder: its files, not the controller, set its pace). Prints per case the best and the
median wall time of a run and the median CPU time of the thread (which a loaded machine's preemption
does not inflate), the real-time factor (simulated 15 s / time) of each, and the call overhead per
controller step: (py_constant - cpp_paper) / 750, the time a trivial Python step adds over the C++
controller's (itself about 0.1 µs), and the same for the PD.
"""
import math
import statistics
import sys
import time

import quadcosim

SCENARIO = "scenarios/paper/altitude_step.yaml"


class Constant:
    def __init__(self, vehicle):
        w = vehicle["hover_omega_rad_s"]
        self.omega = (w, w, w, w)

    def step(self, obs, ref, dt):
        return self.omega


class AltitudePD:
    parameters = {"kp_z": dict(default=1.0, unit="1/s^2", min=0.0, max=100.0),
                  "kd_z": dict(default=1.4, unit="1/s", min=0.0, max=100.0)}

    def __init__(self, vehicle):
        self.m = vehicle["mass_kg"]
        self.g = vehicle["gravity_m_s2"]
        self.kt4 = 4.0 * vehicle["kt_N_per_rad2_s2"]

    def step(self, obs, ref, dt):
        p, v = obs.p, obs.v
        a = self.kp_z * (ref.p[2] - p[2]) - self.kd_z * v[2]
        w = math.sqrt(max(self.m * (self.g + a), 0.0) / self.kt4)
        return (w, w, w, w)


def fly(scenario, steps):
    sim = quadcosim.Simulation(scenario)
    step = sim.step
    for _ in range(steps):
        step()
    return sim


def main():
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 50
    base = quadcosim.load_scenario(SCENARIO)
    cases = {
        "cpp_paper": base,
        "py_constant": quadcosim.load_scenario(base, controller=Constant),
        "py_pd": quadcosim.load_scenario(base, controller=AltitudePD),
    }
    steps = round(base.duration_s / base.control_period_s)
    times = {name: [] for name in cases}
    times["run_py_pd"] = []
    cpu = {name: [] for name in times}
    for sc in cases.values():
        fly(sc, steps)  # warm-up
    z_end = fly(cases["py_pd"], steps).state["p"][2]
    for i in range(reps):
        for name, sc in cases.items():
            c0, t0 = time.thread_time(), time.perf_counter()
            fly(sc, steps)
            times[name].append(time.perf_counter() - t0)
            cpu[name].append(time.thread_time() - c0)
        if i % 5 == 0:
            c0, t0 = time.thread_time(), time.perf_counter()
            quadcosim.run(cases["py_pd"])
            times["run_py_pd"].append(time.perf_counter() - t0)
            cpu["run_py_pd"].append(time.thread_time() - c0)
    print(f"{SCENARIO}: {base.duration_s:g} s simulated, {steps} controller steps, "
          f"{round(base.duration_s / base.plant_period_s)} plant ticks; {reps} repetitions, interleaved "
          f"(py_pd ends at z = {z_end:.4f} m)")
    print(f"  {'case':12s} {'wall best ms':>12s} {'median':>8s} {'cpu median':>10s}   x real time: "
          f"{'wall best':>9s} {'median':>8s} {'cpu median':>10s}")
    for name, t in times.items():
        best, median, c = min(t), statistics.median(t), statistics.median(cpu[name])
        print(f"  {name:12s} {best * 1e3:12.3f} {median * 1e3:8.3f} {c * 1e3:10.3f}                "
              f"{base.duration_s / best:9.0f} {base.duration_s / median:8.0f} {base.duration_s / c:10.0f}")
    for stat, source, f in [("wall best", times, min), ("wall median", times, statistics.median),
                            ("cpu median", cpu, statistics.median)]:
        overhead = (f(source["py_constant"]) - f(source["cpp_paper"])) / steps
        pd = (f(source["py_pd"]) - f(source["cpp_paper"])) / steps
        print(f"  per controller step ({stat}): trivial Python step +{overhead * 1e6:.2f} µs, "
              f"scalar PD +{pd * 1e6:.2f} µs over the C++ controller")


if __name__ == "__main__":
    main()
