#include "model/vehicle_presets.hpp"

#include <array>

namespace quadcosim::model {

namespace {

// The paper's vehicle: Table 1 (the defaults of VehicleParams).
VehicleParams paper() { return {}; }

// Crazyflie 2.0 (Bitcraze), from the system identification of J. Förster, "System Identification of
// the Crazyflie 2.0 Nano Quadrocopter", BSc thesis, ETH Zurich, 2015: mass, the whole inertia tensor
// (products included), the thrust coefficient and the torque-to-thrust ratio.
VehicleParams crazyflie2() {
  VehicleParams v;
  v.mass_kg = 0.027;
  v.Ixx_kg_m2 = 16.571710e-6;
  v.Iyy_kg_m2 = 16.655602e-6;
  v.Izz_kg_m2 = 29.261652e-6;
  v.Ixy_kg_m2 = 0.830806e-6;
  v.Ixz_kg_m2 = 0.718277e-6;
  v.Iyz_kg_m2 = 1.800197e-6;
  v.layout = RotorLayout::kX;
  v.arm_length_m = 0.046;                          // half the 92 mm motor-to-motor diagonal
  v.kt_N_per_rad2_s2 = 1.28192e-8;                 // k_F
  v.km_Nm_per_rad2_s2 = 1.28192e-8 * 5.964552e-3;  // k_F times the torque-to-thrust ratio k_M [m]
  v.spin = {+1, -1, +1, -1};                       // front-left (M4) clockwise, front-right (M1) counter-clockwise
  v.motor.omega_max_rad_s = 2618.0;                // 25,000 rpm
  // Förster's identified rotor drag (the diagonal of his K_aero, on the sum of the rotor speeds, which
  // is k_d per rotor at the hubs; RotorPy's crazyflie_params.py carries the same two numbers). Off
  // until aero.rotor_aero is turned on; he identified no flapping moment or translational lift.
  v.aero.rotor_drag_k_d = 10.2506e-7;
  v.aero.inflow_k_z = 7.5530e-7;
  return v;
}

// AscTec Hummingbird, as the RotorS simulator models it (F. Furrer, M. Burri, M. Achtelik, R. Siegwart,
// "RotorS - A Modular Gazebo MAV Simulator Framework", in Robot Operating System (ROS): The Complete
// Reference, vol. 1, Springer, 2016; its body properties from J. Wang et al., "Novel Dynamic Inversion
// Architecture Design for Quadrocopter Control", 2011): '+' frame, 0.17 m arms, the motor and moment
// constants and first-order motors with their time constants. The mass and inertia add RotorS's four
// 9 g rotors, as point masses at the hubs, to its 0.68 kg body.
VehicleParams hummingbird() {
  constexpr double kRotorMass = 0.009, kArm = 0.17;
  VehicleParams v;
  v.mass_kg = 0.68 + 4.0 * kRotorMass;
  v.Ixx_kg_m2 = 0.007 + 2.0 * kRotorMass * kArm * kArm;  // the rotors on the y axis
  v.Iyy_kg_m2 = 0.007 + 2.0 * kRotorMass * kArm * kArm;  // the rotors on the x axis
  v.Izz_kg_m2 = 0.012 + 4.0 * kRotorMass * kArm * kArm;
  v.layout = RotorLayout::kPlus;
  v.arm_length_m = kArm;
  v.kt_N_per_rad2_s2 = 8.54858e-6;           // motor constant
  v.km_Nm_per_rad2_s2 = 8.54858e-6 * 0.016;  // times the moment constant [m]
  v.spin = {+1, -1, +1, -1};                 // front and back clockwise, left and right counter-clockwise
  v.motor.model = MotorModel::kFirstOrder;
  v.motor.tau_up_s = 0.0125;
  v.motor.tau_down_s = 0.025;
  v.motor.omega_max_rad_s = 838.0;
  // Rotor drag and inflow as RotorPy models the Hummingbird (Folk, Paulos, Kumar, 2023,
  // hummingbird_params.py, after Svacha, Mohta, Kumar, ICUAS 2017, an order of magnitude below the
  // 1e-3 it found too large). Off until aero.rotor_aero is turned on; no flapping or translational lift.
  v.aero.rotor_drag_k_d = 1.19e-4;
  v.aero.inflow_k_z = 2.32e-4;
  return v;
}

// A 450 mm-class quadrotor (DJI F450 frame), the parameter set of Q. Quan, "Introduction to Multicopter
// Design and Control", Springer, 2017 (used by its examples and the RflySim platform): mass, inertia,
// thrust and torque coefficients c_T and c_M, the motor time constant T_m, and the top speed
// C_R + w_b = 1148 - 141.4 rad/s of its throttle-to-speed line at full throttle.
VehicleParams f450() {
  VehicleParams v;
  v.mass_kg = 1.4;
  v.Ixx_kg_m2 = 0.0211;
  v.Iyy_kg_m2 = 0.0219;
  v.Izz_kg_m2 = 0.0366;
  v.layout = RotorLayout::kX;
  v.arm_length_m = 0.225;
  v.kt_N_per_rad2_s2 = 1.105e-5;
  v.km_Nm_per_rad2_s2 = 1.779e-7;
  v.spin = {+1, -1, +1, -1};
  v.motor.model = MotorModel::kFirstOrder;
  v.motor.tau_up_s = 0.02;
  v.motor.tau_down_s = 0.02;
  v.motor.omega_max_rad_s = 1148.0 - 141.4;
  return v;
}

// AscTec Firefly hexarotor, as the RotorS simulator models it (F. Furrer, M. Burri, M. Achtelik,
// R. Siegwart, "RotorS - A Modular Gazebo MAV Simulator Framework", in Robot Operating System (ROS): The
// Complete Reference, vol. 1, Springer, 2016; rotors_description/urdf/firefly.xacro of
// github.com/ethz-asl/rotors_simulator): six rotors on 0.215 m arms at 30, 90, ..., 330 deg (hex_x),
// front-left turning counter-clockwise and the others alternating, its 1.5 kg body and body inertia,
// the motor constant 8.54858e-6 N/(rad/s)^2 and moment constant 0.016 m, first-order motors of
// 0.0125 s up and 0.025 s down (the revision of the file most of its history carries; a later one sets
// both to 0.025 s), 838 rad/s at most. As for the Hummingbird above, the mass and inertia add its six
// 5 g rotors as point masses at the hubs.
VehicleParams firefly() {
  constexpr double kRotorMass = 0.005, kArm = 0.215;
  VehicleParams v;
  v.set_layout(RotorLayout::kHexX);
  v.arm_length_m = kArm;
  // Hubs at (L cos a, L sin a), a = 30 + 60 k deg: sum y^2 = 3 L^2, sum x^2 = 3 L^2, sum r^2 = 6 L^2.
  v.mass_kg = 1.5 + 6.0 * kRotorMass;
  v.Ixx_kg_m2 = 0.0347563 + 3.0 * kRotorMass * kArm * kArm;
  v.Iyy_kg_m2 = 0.0458929 + 3.0 * kRotorMass * kArm * kArm;
  v.Izz_kg_m2 = 0.0977 + 6.0 * kRotorMass * kArm * kArm;
  v.kt_N_per_rad2_s2 = 8.54858e-6;           // motor constant
  v.km_Nm_per_rad2_s2 = 8.54858e-6 * 0.016;  // times the moment constant [m]
  // Rotor 1 front-left (RotorS's front_left, ccw), 2 front-right (cw), 3 right (ccw), 4 rear-right
  // (cw), 5 rear-left (ccw), 6 left (cw): +1 is clockwise seen from above.
  v.spin = {-1, +1, -1, +1, -1, +1, +1, -1};
  v.motor.model = MotorModel::kFirstOrder;
  v.motor.tau_up_s = 0.0125;
  v.motor.tau_down_s = 0.025;
  v.motor.omega_max_rad_s = 838.0;
  return v;
}

const std::array<VehiclePreset, 5>& table() {
  static const std::array<VehiclePreset, 5> presets = {{
      {"paper", "the paper's 1.96 kg '+' quadrotor (Table 1)", "the paper's Table 1", paper()},
      {"crazyflie2", "Bitcraze Crazyflie 2.0, 27 g 'x' nano quadrotor, full inertia tensor",
       "J. Foerster, System Identification of the Crazyflie 2.0 Nano Quadrocopter, ETH Zurich, 2015", crazyflie2()},
      {"hummingbird", "AscTec Hummingbird, 0.72 kg '+' quadrotor with first-order motors",
       "F. Furrer et al., RotorS - A Modular Gazebo MAV Simulator Framework, Springer, 2016 (body from J. Wang et "
       "al., 2011)",
       hummingbird()},
      {"f450", "450 mm-class 'x' quadrotor (DJI F450 frame), 1.4 kg, first-order motors",
       "Q. Quan, Introduction to Multicopter Design and Control, Springer, 2017", f450()},
      {"firefly", "AscTec Firefly, 1.53 kg hexarotor (hex_x) with first-order motors",
       "F. Furrer et al., RotorS - A Modular Gazebo MAV Simulator Framework, Springer, 2016 (firefly.xacro of "
       "ethz-asl/rotors_simulator)",
       firefly()},
  }};
  return presets;
}

}  // namespace

std::span<const VehiclePreset> vehicle_presets() { return table(); }

const VehiclePreset* find_vehicle_preset(std::string_view name) {
  for (const VehiclePreset& p : table()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::vector<std::string> vehicle_preset_list() {
  std::vector<std::string> names;
  for (const VehiclePreset& p : table()) names.emplace_back(p.name);
  return names;
}

std::string vehicle_preset_names() {
  std::string names;
  for (const std::string& n : vehicle_preset_list()) names.append(names.empty() ? "" : ", ").append(n);
  return names;
}

}  // namespace quadcosim::model
