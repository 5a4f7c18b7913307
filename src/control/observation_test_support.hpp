// Test support: the observation a controller is stepped with, built from a vehicle's state or outputs
// as sim::ControllerNode builds it from the plant's topics (fresh samples: age 0).
#pragma once

#include "control/controller.hpp"
#include "model/attitude.hpp"
#include "model/quadrotor.hpp"

namespace quadcosim::control::test {

/// Position, velocity, attitude (and its Z-Y-X angles) and body rates of `x` (a model::State or
/// model::Outputs); the accelerometer left at zero.
template <class X>
Observation observe_motion(const X& x) {
  Observation o;
  o.p_W = x.p_W;
  o.v_W = x.v_W;
  o.q_WB = x.q_WB;
  const model::Euler e = model::euler_from_quaternion(x.q_WB);
  o.roll_rad = e.roll_rad;
  o.pitch_rad = e.pitch_rad;
  o.yaw_rad = e.yaw_rad;
  o.w_B = x.w_B;
  o.age_s = 0.0;
  return o;
}

/// The observation of the state `x` (no accelerometer).
inline Observation observe(const model::State& x) { return observe_motion(x); }

/// The observation sim::ControllerNode builds from the plant's outputs `y`, the accelerometer included.
inline Observation observe(const model::Outputs& y) {
  Observation o = observe_motion(y);
  o.specific_force_B = y.specific_force_B;
  return o;
}

}  // namespace quadcosim::control::test
