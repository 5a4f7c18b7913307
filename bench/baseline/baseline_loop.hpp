// BASELINE, not part of the framework: the smallest hand-written loop of the same vehicle model that
// we could write, to measure how close the framework's co-simulation comes to the machine's floor.
// Plain doubles, no messages, no transport, no allocation: one 100 Hz RK4 step of the 6-DOF rigid
// body (ideal motors, full gyroscopic term, same equations as model::Quadrotor::derivative) and, on
// every second tick, a 50 Hz controller doing the same kinds of work as control::FlightController
// (Z-Y-X Euler angles from the quaternion by atan2, attitude PD (the LQR gains), altitude PD with
// gravity feedforward and tilt compensation, inverse mixer, clamp, square roots). Ground contact
// and stale-data safety are left out: the loop is a floor, not a second implementation.
#pragma once

#include <algorithm>
#include <cmath>

namespace quadcosim::baseline {

struct BaselineVehicle {
  double mass_kg, gravity_m_s2;
  double inertia_kg_m2[3];
  double mixer[4][4];          ///< omega^2 -> U1 [N], U2..U4 [N m] (eq. (4))
  double mixer_inverse[4][4];  ///< U -> omega^2
  double omega_max_rad_s;
};

struct BaselineGains {
  double k_angle[3], k_rate[3];  ///< torque = k_angle (des - angle) - k_rate rate [N m/rad, N m s/rad]
  double kp_z, kd_z;             ///< [N/m], [N s/m]
  double min_cos_tilt;
};

/// p (3), v (3), q (w, x, y, z), body rates (3): 13 doubles.
struct BaselineState {
  double x[13] = {0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0};
};

class BaselineLoop {
 public:
  BaselineLoop(const BaselineVehicle& v, const BaselineGains& g, double z_des_m) : v_(v), g_(g), z_des_m_(z_des_m) {}

  /// One 100 Hz tick; the controller runs on even ticks.
  void tick(long k, double dt_s) {
    if (k % 2 == 0) control(2.0 * dt_s);
    rk4(dt_s);
  }
  const BaselineState& state() const { return s_; }

 private:
  void derivative(const double* x, double* d) const {
    double U[4];
    for (int r = 0; r < 4; ++r) {
      U[r] = v_.mixer[r][0] * w2_[0] + v_.mixer[r][1] * w2_[1] + v_.mixer[r][2] * w2_[2] + v_.mixer[r][3] * w2_[3];
    }
    const double qw = x[6], qx = x[7], qy = x[8], qz = x[9];
    const double a = U[0] / v_.mass_kg;
    d[0] = x[3];
    d[1] = x[4];
    d[2] = x[5];
    d[3] = 2.0 * (qx * qz + qw * qy) * a;
    d[4] = 2.0 * (qy * qz - qw * qx) * a;
    d[5] = (1.0 - 2.0 * (qx * qx + qy * qy)) * a - v_.gravity_m_s2;
    const double wx = x[10], wy = x[11], wz = x[12];
    const double* I = v_.inertia_kg_m2;
    d[10] = (U[1] - (wy * I[2] * wz - wz * I[1] * wy)) / I[0];
    d[11] = (U[2] - (wz * I[0] * wx - wx * I[2] * wz)) / I[1];
    d[12] = (U[3] - (wx * I[1] * wy - wy * I[0] * wx)) / I[2];
    d[6] = -0.5 * (qx * wx + qy * wy + qz * wz);
    d[7] = 0.5 * (qw * wx + qy * wz - qz * wy);
    d[8] = 0.5 * (qw * wy + qz * wx - qx * wz);
    d[9] = 0.5 * (qw * wz + qx * wy - qy * wx);
  }

  void rk4(double h) {
    double k1[13], k2[13], k3[13], k4[13], y[13];
    derivative(s_.x, k1);
    for (int i = 0; i < 13; ++i) y[i] = s_.x[i] + 0.5 * h * k1[i];
    derivative(y, k2);
    for (int i = 0; i < 13; ++i) y[i] = s_.x[i] + 0.5 * h * k2[i];
    derivative(y, k3);
    for (int i = 0; i < 13; ++i) y[i] = s_.x[i] + h * k3[i];
    derivative(y, k4);
    for (int i = 0; i < 13; ++i) s_.x[i] += h * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0;
    const double n = std::sqrt(s_.x[6] * s_.x[6] + s_.x[7] * s_.x[7] + s_.x[8] * s_.x[8] + s_.x[9] * s_.x[9]);
    for (int i = 6; i < 10; ++i) s_.x[i] /= n;
  }

  void control(double /*dt_s*/) {
    const double* x = s_.x;
    const double w = x[6], qx = x[7], qy = x[8], qz = x[9];
    const double roll = std::atan2(2.0 * (w * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy));
    const double pitch =
        std::atan2(2.0 * (w * qy - qx * qz), std::hypot(1.0 - 2.0 * (qy * qy + qz * qz), 2.0 * (qx * qy + w * qz)));
    const double yaw = std::atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
    const double angle[3] = {roll, pitch, yaw};
    double U[4];
    for (int a = 0; a < 3; ++a) U[a + 1] = g_.k_angle[a] * (0.0 - angle[a]) - g_.k_rate[a] * x[10 + a];
    const double tilt = std::max(std::cos(roll) * std::cos(pitch), g_.min_cos_tilt);
    U[0] = std::max(0.0, (v_.mass_kg * v_.gravity_m_s2 + g_.kp_z * (z_des_m_ - x[2]) - g_.kd_z * x[5]) / tilt);
    const double hi = v_.omega_max_rad_s * v_.omega_max_rad_s;
    for (int r = 0; r < 4; ++r) {
      const double d = v_.mixer_inverse[r][0] * U[0] + v_.mixer_inverse[r][1] * U[1] + v_.mixer_inverse[r][2] * U[2] +
                       v_.mixer_inverse[r][3] * U[3];
      w2_[r] = std::clamp(d, 0.0, hi);  // ideal motors: the plant uses omega^2 = the command squared
      omega_[r] = std::sqrt(w2_[r]);
    }
  }

  BaselineVehicle v_;
  BaselineGains g_;
  double z_des_m_;
  BaselineState s_;
  double w2_[4] = {0, 0, 0, 0};
  double omega_[4] = {0, 0, 0, 0};
};

}  // namespace quadcosim::baseline
