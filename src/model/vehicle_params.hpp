// Physical parameters of a quadrotor. Defaults are the paper's vehicle (Table 1).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "model/aero.hpp"
#include "model/rotor_vector.hpp"

namespace quadcosim::model {

/// Arrangement of the rotors in the body (FLU) frame. The standard layouts put N rotors evenly on a
/// circle of radius arm_length_m, numbered clockwise seen from above; rotor 1 on the nose (the '+'
/// kinds) or half a spacing counter-clockwise of it (the 'x' kinds). docs/model.md, "Rotor layouts".
enum class RotorLayout {
  /// '+': rotor 1 on +x (nose), 2 on -y (right), 3 on -x, 4 on +y (left); the paper's eq. (4).
  kPlus,
  /// 'x': the '+' arrangement turned 45 deg counter-clockwise seen from above: rotor 1 front-left,
  /// 2 front-right, 3 rear-right, 4 rear-left.
  kX,
  kHexPlus,   ///< six rotors, rotor 1 on the nose, then every 60 deg clockwise
  kHexX,      ///< six rotors, rotor 1 at +30 deg (front-left), then every 60 deg clockwise
  kOctoPlus,  ///< eight rotors, rotor 1 on the nose, then every 45 deg clockwise
  kOctoX,     ///< eight rotors, rotor 1 at +22.5 deg (front-left), then every 45 deg clockwise
  kCustom,    ///< rotor_count rotors at rotor_positions_m (thrust along +z_B for each)
};

/// The layouts by their YAML names, in the order of the enum.
inline constexpr std::array<RotorLayout, 7> kRotorLayouts = {
    RotorLayout::kPlus,     RotorLayout::kX,     RotorLayout::kHexPlus, RotorLayout::kHexX,
    RotorLayout::kOctoPlus, RotorLayout::kOctoX, RotorLayout::kCustom};

/// The rotor count of a standard layout (4, 6 or 8); 0 for kCustom (its count is the vehicle's).
int layout_rotor_count(RotorLayout layout);

/// How the motor speed follows the commanded speed.
enum class MotorModel {
  kIdeal,       ///< speed equals the (clamped) command instantly, as in the paper.
  kFirstOrder,  ///< first-order lag with separate time constants for spinning up and down.
};

/// Which rotational dynamics the plant integrates.
enum class GyroscopicModel {
  kFull,        ///< eq. (8)/(10): I dw = tau - w x (I w).
  kSimplified,  ///< eq. (11): I dw = tau (gyroscopic coupling dropped).
};

struct MotorParams {
  MotorModel model = MotorModel::kIdeal;
  double tau_up_s = 0.02;        ///< [s] time constant when the command is above the current speed.
  double tau_down_s = 0.04;      ///< [s] time constant when the command is below the current speed.
  double omega_min_rad_s = 0.0;  ///< [rad/s] lowest speed a motor turns at (0: may stop).
  /// [rad/s] highest speed. 12000 rad/s gives a thrust-to-weight ratio of about 6.2 with Table 1's
  /// k_t, above the peak the paper's altitude step asks for (about 8400 rad/s).
  double omega_max_rad_s = 12000.0;
};

struct VehicleParams {
  double mass_kg = 1.96;
  double gravity_m_s2 = 9.81;
  double Ixx_kg_m2 = 0.0149;
  double Iyy_kg_m2 = 0.0153;
  double Izz_kg_m2 = 0.0532;
  /// Products of inertia: the off-diagonal entries of the inertia tensor about the centre of mass in
  /// the body frame, J_xy = -sum(m x y) (as a URDF <inertia> or an identified tensor gives them). All
  /// zero (the paper's vehicle): the body axes are principal axes and the model takes the diagonal path.
  double Ixy_kg_m2 = 0.0;
  double Ixz_kg_m2 = 0.0;
  double Iyz_kg_m2 = 0.0;
  double arm_length_m = 0.59;           ///< [m] rotor axis to centre of mass (L).
  double kt_N_per_rad2_s2 = 2.06e-7;    ///< thrust coefficient k_t [N/(rad/s)^2], eq. (1).
  double km_Nm_per_rad2_s2 = 1.01e-10;  ///< drag-torque coefficient k_m [N m/(rad/s)^2], eq. (2).
  RotorLayout layout = RotorLayout::kPlus;
  /// How many rotors (4..kMaxRotors): the layout's for a standard one (set_layout keeps them equal), the
  /// number of rotor_positions_m in use for kCustom.
  int rotor_count = 4;
  /// Sign of each rotor's reaction torque about +z_B (+1: the rotor spins clockwise seen from above,
  /// so its drag pushes the body counter-clockwise); the first rotor_count entries are used. The paper's
  /// eq. (4): rotors 1 and 3 positive. Alternating by default; any pattern whose mixer keeps full row
  /// rank is accepted (a quadrotor's must alternate).
  std::array<int, kMaxRotors> spin = {+1, -1, +1, -1, +1, -1, +1, -1};
  /// kCustom: rotor i's hub in the body frame [m] (the first rotor_count entries). The thrust axes stay
  /// +z_B; z only moves where the per-rotor aerodynamics act.
  std::array<Eigen::Vector3d, kMaxRotors> rotor_positions_m{};
  MotorParams motor;
  GyroscopicModel gyroscopic = GyroscopicModel::kFull;
  AeroParams aero;  ///< drag and ground effect (all zero: none, as in the paper)

  /// [rad/s] speed at which N equal rotors carry the weight: sqrt(m g / (N k_t)).
  double hover_omega_rad_s() const;
  /// Sets the layout, and the rotor count to a standard layout's (kCustom keeps rotor_count).
  void set_layout(RotorLayout l);
  /// The inertia tensor J [kg m^2]: Ixx, Iyy, Izz on the diagonal, the products off it.
  Eigen::Matrix3d inertia_tensor() const;
  /// True when every product of inertia is zero (the body axes are principal axes).
  bool principal_axes() const { return Ixy_kg_m2 == 0.0 && Ixz_kg_m2 == 0.0 && Iyz_kg_m2 == 0.0; }
};

/// An interval of accepted values; each end either includes its value (closed) or not (open).
struct Range {
  enum class End { kClosed, kOpen };
  double min = 0.0, max = 0.0;
  End min_end = End::kClosed, max_end = End::kClosed;

  /// True when `v` is finite and inside.
  bool contains(double v) const;
  /// "[1e-06, 1e+12]", "(0, 1000]": the form errors and tables print.
  std::string text() const;
};

/// One vehicle parameter, declared once: its YAML path, unit, accepted values, meaning and the member
/// of VehicleParams it binds to. The YAML loader (scenario `vehicle:` sections and vehicle files),
/// validate(), `quadcosim params --vehicle`, sweeps and docs/model.md all read this one table.
struct VehicleParameter {
  enum class Kind {
    kNumber,  ///< a double: `range`, `ref`
    kChoice,  ///< a named option: `choices`, `choice_of`, `set_choice`
    kSigns,   ///< the rotor spin signs (+1 or -1 each, one per rotor): `signs`
    kRotors,  ///< a custom layout's rotors: a list of {position_m: [x, y, z], spin: 1 or -1}
  };

  /// YAML path: "mass_kg", "motor.tau_up_s"; one component of a 3-vector is "aero.linear_drag_N_s_m.x".
  std::string_view name;
  std::string_view unit;  ///< SI unit; "" when dimensionless or not a number
  std::string_view meaning;
  Kind kind = Kind::kNumber;
  Range range;                                                      ///< kNumber: the values accepted
  std::vector<std::string_view> choices;                            ///< kChoice: the values accepted
  double& (*ref)(VehicleParams&) = nullptr;                         ///< kNumber: the member
  std::string_view (*choice_of)(const VehicleParams&) = nullptr;    ///< kChoice: current value
  void (*set_choice)(VehicleParams&, std::string_view) = nullptr;   ///< kChoice: one of `choices`
  std::array<int, kMaxRotors>& (*signs)(VehicleParams&) = nullptr;  ///< kSigns: the member

  /// kNumber: the value in `v`.
  double get(const VehicleParams& v) const;
  /// The value in `v` as text: "1.96", "plus", "[1, -1, 1, -1]" (one sign per rotor), the rotors'
  /// positions for kRotors ("[] (layout not custom)" otherwise).
  std::string text(const VehicleParams& v) const;
  /// YAML layout of `name`: the section ("" at the top, "motor", "aero"), the key within it, and the
  /// vector component (0, 1, 2 for .x/.y/.z; -1 for a scalar).
  std::string_view section() const;
  std::string_view key() const;
  int component() const;
};

/// Every vehicle parameter, in the order files and tables list them (a 3-vector as three
/// consecutive entries .x, .y, .z).
const std::vector<VehicleParameter>& vehicle_parameters();

/// The entry whose YAML path is `name` ("mass_kg", "motor.tau_up_s", "aero.linear_drag_N_s_m.x"), or
/// nullptr.
const VehicleParameter* find_vehicle_parameter(std::string_view name);

/// Returns an empty string when `p` is physically meaningful, else a message naming the first bad field
/// (e.g. "mass_kg must be in [1e-06, 1e+12] kg, got -1"): every number within its declared range, then
/// the rules between fields (omega_min below omega_max, 4..8 rotors, a standard layout's rotor count, spin
/// signs +-1 (a quadrotor's balanced and alternating), a custom layout's positions finite and distinct,
/// a mixer of full row rank, an inertia tensor that is positive definite).
std::string validate(const VehicleParams& p);

/// The rotor rules of validate() alone (count, signs, custom positions, the mixer's rank); "" when met.
std::string validate_rotors(const VehicleParams& p);

/// Empty when RK4 with step `step_s` [s] is stable for the motor lag (step <= 2 tau; RK4's limit on a
/// decaying mode is 2.785 tau), else a message naming the time constant and the substeps needed.
/// Always empty for ideal motors.
std::string validate_step(const VehicleParams& p, double step_s, int substeps);

const char* to_string(RotorLayout layout);
const char* to_string(MotorModel model);
const char* to_string(GyroscopicModel model);

}  // namespace quadcosim::model
