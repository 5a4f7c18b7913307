"""A controller that flies on what an autopilot has: the IMU, a GNSS receiver, a barometer and a
magnetometer, never the Pose or Velocity topics (scenarios/examples/gnss_hold.yaml, docs/sensors.md).

Estimation, by complementary filters (no Kalman gain, no latency compensation: a sketch of what an
autopilot's estimator does, kept short):
- attitude: roll and pitch from the IMU's orientation; heading from the magnetometer, tilt-compensated
  with that roll and pitch, corrected by the site's declination (a parameter, as an autopilot reads it
  from a world magnetic model);
- position and velocity: predicted every step from the accelerometer (specific force turned into the
  world frame, gravity added back), corrected by each new GNSS fix (north and east from the first fix,
  on a flat-earth step from the home position, a parameter, over the few metres flown) and its
  velocity, and vertically by each new barometer sample (height above the first one: it takes off
  from the ground).
Control: PD on the estimated position, a tilt limit, P attitude (on the magnetic heading) and P rate
loops, allocated through the vehicle's mixer. Before the first GNSS fix it holds level and climbs on
the barometer alone.
"""
import math

import numpy as np

R_EARTH_M = 6378137.0  # WGS-84 equatorial radius [m]


class GnssHold:
    parameters = {
        "kp_xy": dict(default=1.0, unit="1/s^2", min=0.0, max=20.0, description="horizontal position P gain"),
        "kd_xy": dict(default=1.6, unit="1/s", min=0.0, max=20.0, description="horizontal velocity gain"),
        "kp_z": dict(default=3.0, unit="1/s^2", min=0.0, max=50.0, description="height P gain"),
        "kd_z": dict(default=3.0, unit="1/s", min=0.0, max=50.0, description="vertical velocity gain"),
        "k_att": dict(default=6.0, unit="1/s", min=0.0, max=50.0, description="roll/pitch: rate asked per rad"),
        "k_yaw": dict(default=1.5, unit="1/s", min=0.0, max=50.0, description="yaw: rate asked per rad"),
        "k_rate": dict(default=20.0, unit="1/s", min=0.0, max=200.0, description="roll/pitch rate gain"),
        "k_rate_yaw": dict(default=2.0, unit="1/s", min=0.0, max=200.0, description="yaw rate gain"),
        "max_tilt": dict(default=0.35, unit="rad", min=0.05, max=1.0, description="tilt limit"),
        "w_gnss": dict(default=1.0, unit="rad/s", min=0.01, max=10.0, description="GNSS correction bandwidth"),
        "w_baro": dict(default=2.0, unit="rad/s", min=0.01, max=10.0, description="barometer correction bandwidth"),
        "declination_deg": dict(default=0.0, unit="deg", min=-180.0, max=180.0,
                                description="magnetic declination at the site, east of true north"),
        "home_latitude_deg": dict(default=0.0, unit="deg", min=-90.0, max=90.0,
                                  description="latitude of the world origin (the home a ground station sets)"),
        "home_longitude_deg": dict(default=0.0, unit="deg", min=-180.0, max=180.0,
                                   description="longitude of the world origin"),
    }
    outputs = ("x_est", "y_est", "z_est", "yaw_mag", "roll_des", "pitch_des", "yaw_des")

    def __init__(self, vehicle):
        self.mass = float(vehicle["mass_kg"])
        self.g = float(vehicle["gravity_m_s2"])
        self.inertia = np.array([float(vehicle["Ixx_kg_m2"]), float(vehicle["Iyy_kg_m2"]),
                                 float(vehicle["Izz_kg_m2"])])
        self.mixer_inverse = np.array(vehicle["mixer_inverse"], dtype=float)
        self.omega_max = float(vehicle["motor.omega_max_rad_s"])
        self.reset()

    def reset(self):
        self.p = np.zeros(3)  # estimated position [m]: east, north from home; up from the first baro sample
        self.v = np.zeros(3)  # estimated velocity [m/s], ENU
        self.fixed = False    # a GNSS fix has come
        self.baro0 = None     # the first barometer altitude [m]
        self.baro_t = self.gnss_t = None

    def heading(self, obs):
        """Yaw [rad] (x east, counter-clockwise) from the magnetometer, tilt-compensated."""
        b = obs.magnetometer.field
        cr, sr, cp, sp = math.cos(obs.roll), math.sin(obs.roll), math.cos(obs.pitch), math.sin(obs.pitch)
        # The body reading turned into the heading frame: Ry(pitch) Rx(roll) b.
        by = cr * b[1] - sr * b[2]
        bz = sr * b[1] + cr * b[2]
        bx = cp * b[0] + sp * bz
        # Magnetic north lies declination east of true north (+y): at angle pi/2 - D from east, and the
        # body sees it at atan2(by, bx) from its nose.
        yaw = math.pi / 2 - math.radians(self.declination_deg) - math.atan2(by, bx)
        return math.atan2(math.sin(yaw), math.cos(yaw))

    def estimate(self, obs, dt):
        w, x, y, z = obs.q
        rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                             [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                             [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        a = rotation @ obs.f - np.array([0.0, 0.0, self.g])
        self.p += self.v * dt + 0.5 * a * dt * dt
        self.v += a * dt
        baro, gnss = obs.barometer, obs.gnss
        if baro.t is not None and baro.t != self.baro_t:
            dt_baro = dt if self.baro_t is None else baro.t - self.baro_t
            self.baro_t = baro.t
            if self.baro0 is None:
                self.baro0 = baro.altitude
            e = (baro.altitude - self.baro0) - self.p[2]
            self.p[2] += 2 * self.w_baro * dt_baro * e
            self.v[2] += self.w_baro ** 2 * dt_baro * e
        if gnss.t is not None and gnss.t != self.gnss_t and gnss.fix:
            dt_gnss = 0.1 if self.gnss_t is None else gnss.t - self.gnss_t
            self.gnss_t = gnss.t
            home = math.radians(self.home_latitude_deg)
            east = math.radians(gnss.longitude_deg - self.home_longitude_deg) * R_EARTH_M * math.cos(home)
            north = math.radians(gnss.latitude_deg - self.home_latitude_deg) * R_EARTH_M
            if not self.fixed:
                self.fixed = True
                self.p[0:2] = east, north
            e = np.array([east, north]) - self.p[0:2]
            self.p[0:2] += 2 * self.w_gnss * dt_gnss * e
            self.v[0:2] += self.w_gnss ** 2 * dt_gnss * e + 0.5 * (gnss.v[0:2] - self.v[0:2])

    def step(self, obs, ref, dt):
        self.estimate(obs, dt)
        yaw = self.heading(obs)
        a_des = ref.a + self.kp_xy * (ref.p - self.p) + self.kd_xy * (ref.v - self.v)
        a_des[2] = ref.a[2] + self.kp_z * (ref.p[2] - self.p[2]) + self.kd_z * (ref.v[2] - self.v[2])
        if not self.fixed:
            a_des[0:2] = 0.0  # no fix yet: level
        force = self.mass * (a_des + np.array([0.0, 0.0, self.g]))
        force[2] = max(force[2], 0.1 * self.mass * self.g)
        horizontal, limit = math.hypot(force[0], force[1]), math.tan(self.max_tilt) * force[2]
        if horizontal > limit:
            force[0:2] *= limit / horizontal
        z_b = force / np.linalg.norm(force)
        cy, sy = math.cos(yaw), math.sin(yaw)
        pitch_des = math.atan2(cy * z_b[0] + sy * z_b[1], z_b[2])
        roll_des = math.asin(max(-1.0, min(1.0, sy * z_b[0] - cy * z_b[1])))
        w, x, y, z = obs.q  # the thrust: the force's projection on the body z axis
        thrust = max(float(force @ np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])), 0.0)
        yaw_error = math.atan2(math.sin(ref.yaw - yaw), math.cos(ref.yaw - yaw))
        rates_des = np.array([self.k_att * (roll_des - obs.roll), self.k_att * (pitch_des - obs.pitch),
                              self.k_yaw * yaw_error])
        torque = self.inertia * np.array([self.k_rate, self.k_rate, self.k_rate_yaw]) * (rates_des - obs.w)
        squared = self.mixer_inverse @ np.array([thrust, torque[0], torque[1], 0.0])
        # Yaw last and only as much as keeps every rotor within its range with a margin: rotor drag makes
        # yaw torque expensive, and a rotor driven to a limit would tilt the vehicle instead.
        yaw_part, top = self.mixer_inverse[:, 3] * torque[2], self.omega_max ** 2
        room = np.where(yaw_part > 0.0, 0.9 * top - squared, squared - 0.1 * top) / np.maximum(np.abs(yaw_part), 1e-12)
        omega = np.sqrt(np.clip(squared + min(1.0, max(0.0, float(room.min()))) * yaw_part, 0.0, top))
        return omega, (self.p[0], self.p[1], self.p[2], yaw, roll_des, pitch_des, ref.yaw)
