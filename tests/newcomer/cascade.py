"""A controller as a newcomer to quadcosim writes one: a cascade of PD position (or altitude), P attitude
and P rate loops, allocated through the vehicle's mixer. It shares no code with quadcosim's own
controllers; the tests of tests/newcomer fly it through every shipped scenario (docs/controllers.md).

Position mode: a_des = a_ref + kp (p_ref - p) + kd (v_ref - v); attitude mode: the roll, pitch and yaw
setpoints, with a_des_z = kp_z (z_ref - z) - kd_z v_z. The thrust vector m (a_des + g e_z) gives the
tilt to fly (limited to max_tilt) and the collective thrust (its projection on the body z axis); the
attitude error asks for body rates (k_att), the rate error for torques (k_rate, through the inertia).
"""
import math

import numpy as np


class Cascade:
    parameters = {
        "kp_xy": dict(default=1.44, unit="1/s^2", min=0.0, max=100.0, description="horizontal position P gain"),
        "kd_xy": dict(default=1.9, unit="1/s", min=0.0, max=100.0, description="horizontal velocity gain"),
        "kp_z": dict(default=4.0, unit="1/s^2", min=0.0, max=100.0, description="altitude P gain"),
        "kd_z": dict(default=3.2, unit="1/s", min=0.0, max=100.0, description="vertical velocity gain"),
        "k_att": dict(default=5.0, unit="1/s", min=0.0, max=100.0, description="roll/pitch: rate asked per rad"),
        "k_att_yaw": dict(default=1.5, unit="1/s", min=0.0, max=100.0, description="yaw: rate asked per rad"),
        "k_rate": dict(default=18.0, unit="1/s", min=0.0, max=200.0, description="roll/pitch rate gain"),
        "k_rate_yaw": dict(default=8.0, unit="1/s", min=0.0, max=200.0, description="yaw rate gain"),
        "max_tilt": dict(default=0.6, unit="rad", min=0.05, max=1.2, description="tilt limit"),
    }
    outputs = ("thrust_N", "roll_des", "pitch_des")

    def __init__(self, vehicle):
        self.mass = float(vehicle["mass_kg"])
        self.g = float(vehicle["gravity_m_s2"])
        self.inertia = np.array([float(vehicle["Ixx_kg_m2"]), float(vehicle["Iyy_kg_m2"]),
                                 float(vehicle["Izz_kg_m2"])])
        self.mixer_inverse = np.array(vehicle["mixer_inverse"], dtype=float)
        self.omega_max = float(vehicle["motor.omega_max_rad_s"])

    @staticmethod
    def wrap(angle):
        return math.atan2(math.sin(angle), math.cos(angle))

    def step(self, obs, ref, dt):
        p, v = obs.p, obs.v
        if ref.mode == "position":
            a_des = ref.a + self.kp_xy * (ref.p - p) + self.kd_xy * (ref.v - v)
            a_des[2] = ref.a[2] + self.kp_z * (ref.p[2] - p[2]) + self.kd_z * (ref.v[2] - v[2])
        else:
            a_des = np.array([0.0, 0.0, self.kp_z * (ref.p[2] - p[2]) - self.kd_z * v[2]])
        force = self.mass * (a_des + np.array([0.0, 0.0, self.g]))
        force[2] = max(force[2], 0.1 * self.mass * self.g)
        yaw_des = ref.yaw
        if ref.mode == "position":
            # Limit the tilt: the horizontal part of the force at most tan(max_tilt) of the vertical.
            horizontal = math.hypot(force[0], force[1])
            limit = math.tan(self.max_tilt) * force[2]
            if horizontal > limit:
                force[0:2] *= limit / horizontal
            z_b = force / np.linalg.norm(force)
            # The tilt in the heading flown now (not the one asked for), so a vehicle that cannot
            # hold its heading (a weak rotor) still leans towards where it must go.
            cy, sy = math.cos(obs.yaw), math.sin(obs.yaw)
            pitch_des = math.atan2(cy * z_b[0] + sy * z_b[1], z_b[2])
            roll_des = math.asin(max(-1.0, min(1.0, sy * z_b[0] - cy * z_b[1])))
        else:
            roll_des, pitch_des = ref.roll, ref.pitch
        # Collective thrust: the force's projection on the body z axis (the third column of R(q)).
        w, x, y, z = obs.q
        body_z = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
        thrust = max(float(force @ body_z), 0.0)
        if ref.mode != "position":
            thrust = force[2] / max(body_z[2], 0.5)
        errors = np.array([roll_des - obs.roll, pitch_des - obs.pitch, self.wrap(yaw_des - obs.yaw)])
        rates_des = np.array([self.k_att, self.k_att, self.k_att_yaw]) * errors
        torque = self.inertia * np.array([self.k_rate, self.k_rate, self.k_rate_yaw]) * (rates_des - obs.w)
        squared = self.mixer_inverse @ np.array([thrust, torque[0], torque[1], 0.0])
        # Yaw last: rotor drag makes yaw torque expensive, so only as much of it as keeps every rotor
        # within [0, omega_max^2] (clipping instead would add thrust and tilt the vehicle).
        yaw = self.mixer_inverse[:, 3] * torque[2]
        top = self.omega_max ** 2
        share = 1.0
        for base, extra in zip(squared, yaw):
            if base + extra < 0.0 and extra < 0.0:
                share = min(share, max(base, 0.0) / -extra)
            elif base + extra > top and extra > 0.0:
                share = min(share, max(top - base, 0.0) / extra)
        omega = np.sqrt(np.clip(squared + share * yaw, 0.0, top))
        return omega, [thrust, roll_des, pitch_des]
