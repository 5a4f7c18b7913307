#include "model/vehicle_params.hpp"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "model/mixer.hpp"

namespace quadcosim::model {

double VehicleParams::hover_omega_rad_s() const {
  return std::sqrt(mass_kg * gravity_m_s2 / (static_cast<double>(rotor_count) * kt_N_per_rad2_s2));
}

void VehicleParams::set_layout(RotorLayout l) {
  layout = l;
  if (const int n = layout_rotor_count(l); n > 0) rotor_count = n;
}

int layout_rotor_count(RotorLayout layout) {
  switch (layout) {
    case RotorLayout::kPlus:
    case RotorLayout::kX: return 4;
    case RotorLayout::kHexPlus:
    case RotorLayout::kHexX: return 6;
    case RotorLayout::kOctoPlus:
    case RotorLayout::kOctoX: return 8;
    case RotorLayout::kCustom: break;
  }
  return 0;
}

Eigen::Matrix3d VehicleParams::inertia_tensor() const {
  Eigen::Matrix3d J;
  J << Ixx_kg_m2, Ixy_kg_m2, Ixz_kg_m2, Ixy_kg_m2, Iyy_kg_m2, Iyz_kg_m2, Ixz_kg_m2, Iyz_kg_m2, Izz_kg_m2;
  return J;
}

namespace {

using End = Range::End;
constexpr double kHuge = 1e12;

constexpr Range closed(double min, double max) { return {min, max, End::kClosed, End::kClosed}; }
constexpr Range above(double min, double max) { return {min, max, End::kOpen, End::kClosed}; }

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
  return std::string(buf, r.ptr);
}

// One numeric parameter bound to a double inside VehicleParams.
#define QC_NUMBER(NAME, UNIT, RANGE, MEMBER, MEANING)                                   \
  VehicleParameter {                                                                    \
    NAME, UNIT, MEANING, VehicleParameter::Kind::kNumber, RANGE, {},                    \
        [](VehicleParams& v) -> double& { return v.MEMBER; }, nullptr, nullptr, nullptr \
  }

// One named option bound to an enum member; `to_string` names its values.
#define QC_CHOICE(NAME, MEMBER, TYPE, FIRST, SECOND, MEANING)                                                    \
  VehicleParameter {                                                                                             \
    NAME, "", MEANING, VehicleParameter::Kind::kChoice, {}, {to_string(FIRST), to_string(SECOND)}, nullptr,      \
        [](const VehicleParams& v) -> std::string_view { return to_string(v.MEMBER); },                          \
        [](VehicleParams& v, std::string_view c) { v.MEMBER = c == to_string(FIRST) ? FIRST : SECOND; }, nullptr \
  }

std::string signs_text(const std::array<int, kMaxRotors>& s, int n) {
  std::string text = "[";  // appended piece by piece: GCC 12 warns (-Wrestrict) on "[" + std::string
  for (int i = 0; i < n; ++i) text.append(i ? ", " : "").append(std::to_string(s[static_cast<std::size_t>(i)]));
  return text.append("]");
}

std::string rotors_text(const VehicleParams& v) {
  std::string text = "[";
  for (int i = 0; i < v.rotor_count; ++i) {
    const Eigen::Vector3d r = rotor_position_B(v, i);
    text.append(i ? ", " : "")
        .append("{position_m: [")
        .append(number_text(r.x()))
        .append(", ")
        .append(number_text(r.y()))
        .append(", ")
        .append(number_text(r.z()))
        .append("], spin: ")
        .append(std::to_string(v.spin[static_cast<std::size_t>(i)]))
        .append("}");
  }
  return text.append("]");
}

std::vector<VehicleParameter> make_table() {
  const Range drag = closed(0.0, 1e6);
  return {
      QC_NUMBER("mass_kg", "kg", closed(1e-6, kHuge), mass_kg, "vehicle mass m"),
      QC_NUMBER("gravity_m_s2", "m/s^2", above(0.0, 1e3), gravity_m_s2, "gravitational acceleration g (along -z_W)"),
      QC_NUMBER("Ixx_kg_m2", "kg m^2", closed(1e-12, kHuge), Ixx_kg_m2, "moment of inertia about x_B"),
      QC_NUMBER("Iyy_kg_m2", "kg m^2", closed(1e-12, kHuge), Iyy_kg_m2, "moment of inertia about y_B"),
      QC_NUMBER("Izz_kg_m2", "kg m^2", closed(1e-12, kHuge), Izz_kg_m2, "moment of inertia about z_B"),
      QC_NUMBER("Ixy_kg_m2", "kg m^2", closed(-1e6, 1e6), Ixy_kg_m2,
                "product of inertia J_xy = -sum(m x y) (0: principal axes)"),
      QC_NUMBER("Ixz_kg_m2", "kg m^2", closed(-1e6, 1e6), Ixz_kg_m2, "product of inertia J_xz = -sum(m x z)"),
      QC_NUMBER("Iyz_kg_m2", "kg m^2", closed(-1e6, 1e6), Iyz_kg_m2, "product of inertia J_yz = -sum(m y z)"),
      QC_NUMBER("arm_length_m", "m", closed(1e-6, 1e3), arm_length_m, "rotor axis to centre of mass, L"),
      QC_NUMBER("kt_N_per_rad2_s2", "N/(rad/s)^2", closed(1e-20, 1.0), kt_N_per_rad2_s2,
                "thrust coefficient k_t, eq. (1)"),
      QC_NUMBER("km_Nm_per_rad2_s2", "N m/(rad/s)^2", closed(1e-20, 1.0), km_Nm_per_rad2_s2,
                "drag-torque coefficient k_m, eq. (2)"),
      VehicleParameter{"layout",
                       "",
                       "rotor arrangement: plus (rotor 1 on the nose, eq. (4)) or x (turned 45 deg), hex_plus, hex_x, "
                       "octo_plus, octo_x (6 or 8 rotors on the arm circle), custom (the rotors: list)",
                       VehicleParameter::Kind::kChoice,
                       {},
                       {to_string(RotorLayout::kPlus), to_string(RotorLayout::kX), to_string(RotorLayout::kHexPlus),
                        to_string(RotorLayout::kHexX), to_string(RotorLayout::kOctoPlus),
                        to_string(RotorLayout::kOctoX), to_string(RotorLayout::kCustom)},
                       nullptr,
                       [](const VehicleParams& v) -> std::string_view { return to_string(v.layout); },
                       [](VehicleParams& v, std::string_view c) {
                         for (RotorLayout l : kRotorLayouts) {
                           if (c == to_string(l)) v.set_layout(l);
                         }
                       },
                       nullptr},
      VehicleParameter{"rotors",
                       "m",
                       "custom layout: 4 to 8 rotors, each {position_m: [x, y, z], spin: 1 or -1} in the body frame "
                       "(thrust along +z_B); sets layout custom",
                       VehicleParameter::Kind::kRotors,
                       {},
                       {},
                       nullptr,
                       nullptr,
                       nullptr,
                       nullptr},
      VehicleParameter{"spin",
                       "",
                       "reaction-torque sign of each rotor, one per rotor (+1: clockwise from above); alternating by "
                       "default, any pattern whose mixer has full rank (a quadrotor's: two of each, alternating)",
                       VehicleParameter::Kind::kSigns,
                       {},
                       {},
                       nullptr,
                       nullptr,
                       nullptr,
                       [](VehicleParams& v) -> std::array<int, kMaxRotors>& { return v.spin; }},
      QC_CHOICE("gyroscopic", gyroscopic, GyroscopicModel, GyroscopicModel::kFull, GyroscopicModel::kSimplified,
                "rotational dynamics: full (eq. (10), with w x I w) or simplified (eq. (11))"),
      QC_CHOICE("motor.model", motor.model, MotorModel, MotorModel::kIdeal, MotorModel::kFirstOrder,
                "motor speed response: ideal (instant) or first_order (lag)"),
      QC_NUMBER("motor.tau_up_s", "s", closed(1e-6, 1e3), motor.tau_up_s,
                "first-order lag time constant when spinning up"),
      QC_NUMBER("motor.tau_down_s", "s", closed(1e-6, 1e3), motor.tau_down_s,
                "first-order lag time constant when spinning down"),
      QC_NUMBER("motor.omega_min_rad_s", "rad/s", closed(0.0, 1e7), motor.omega_min_rad_s,
                "lowest rotor speed (0: may stop); below omega_max_rad_s"),
      QC_NUMBER("motor.omega_max_rad_s", "rad/s", closed(1e-3, 1e7), motor.omega_max_rad_s, "highest rotor speed"),
      QC_NUMBER("aero.linear_drag_N_s_m.x", "N/(m/s)", drag, aero.linear_drag_N_s_m.x(), "linear body drag along x_B"),
      QC_NUMBER("aero.linear_drag_N_s_m.y", "N/(m/s)", drag, aero.linear_drag_N_s_m.y(), "linear body drag along y_B"),
      QC_NUMBER("aero.linear_drag_N_s_m.z", "N/(m/s)", drag, aero.linear_drag_N_s_m.z(), "linear body drag along z_B"),
      QC_NUMBER("aero.quadratic_drag_N_s2_m2.x", "N/(m/s)^2", drag, aero.quadratic_drag_N_s2_m2.x(),
                "quadratic body drag along x_B"),
      QC_NUMBER("aero.quadratic_drag_N_s2_m2.y", "N/(m/s)^2", drag, aero.quadratic_drag_N_s2_m2.y(),
                "quadratic body drag along y_B"),
      QC_NUMBER("aero.quadratic_drag_N_s2_m2.z", "N/(m/s)^2", drag, aero.quadratic_drag_N_s2_m2.z(),
                "quadratic body drag along z_B"),
      QC_NUMBER("aero.rotor_drag_N_s_m_per_rad_s", "N/((m/s) (rad/s))", closed(0.0, 1.0),
                aero.rotor_drag_N_s_m_per_rad_s, "rotor (induced) drag k_rd, summed over the rotors"),
      QC_NUMBER("aero.ground_effect_rotor_radius_m", "m", closed(0.0, 100.0), aero.ground_effect_rotor_radius_m,
                "rotor radius R for ground effect (0: off)"),
      QC_CHOICE("aero.rotor_aero", aero.rotor_aero, RotorAero, RotorAero::kOff, RotorAero::kOn,
                "per-rotor aerodynamics at the hubs (rotor drag, inflow, flapping, translational lift): true or false"),
      QC_NUMBER("aero.rotor_drag_k_d", "N/((m/s) (rad/s))", closed(0.0, 1.0), aero.rotor_drag_k_d,
                "rotor drag (H-force) k_d per rotor, in its plane, at its hub (with rotor_aero)"),
      QC_NUMBER("aero.inflow_k_z", "N/((m/s) (rad/s))", closed(0.0, 1.0), aero.inflow_k_z,
                "induced-inflow thrust change k_z per rotor, along its axis (with rotor_aero)"),
      QC_NUMBER("aero.flapping_k_flap", "N m/((m/s) (rad/s))", closed(0.0, 1.0), aero.flapping_k_flap,
                "blade-flapping moment k_flap per rotor (with rotor_aero)"),
      QC_NUMBER("aero.translational_lift_k_h", "N/(m/s)^2", closed(0.0, 1e3), aero.translational_lift_k_h,
                "translational lift k_h per rotor, on in-plane airspeed squared (with rotor_aero)"),
  };
}
#undef QC_NUMBER
#undef QC_CHOICE

}  // namespace

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  const bool low_ok = min_end == End::kOpen ? v > min : v >= min;
  const bool high_ok = max_end == End::kOpen ? v < max : v <= max;
  return low_ok && high_ok;
}

std::string Range::text() const {
  std::ostringstream s;
  s << (min_end == End::kOpen ? '(' : '[') << min << ", " << max << (max_end == End::kOpen ? ')' : ']');
  return s.str();
}

double VehicleParameter::get(const VehicleParams& v) const {
  assert(kind == Kind::kNumber);
  // `ref` only names the member; reading through it does not modify `v`.
  return ref(const_cast<VehicleParams&>(v));
}

std::string VehicleParameter::text(const VehicleParams& v) const {
  switch (kind) {
    case Kind::kNumber: return number_text(get(v));
    case Kind::kChoice: return std::string(choice_of(v));
    case Kind::kSigns: return signs_text(v.spin, v.rotor_count);
    case Kind::kRotors: return rotors_text(v);
  }
  return {};
}

std::string_view VehicleParameter::section() const {
  const auto dot = name.find('.');
  return dot == std::string_view::npos ? std::string_view{} : name.substr(0, dot);
}

std::string_view VehicleParameter::key() const {
  std::string_view rest = name;
  if (const auto dot = rest.find('.'); dot != std::string_view::npos) rest = rest.substr(dot + 1);
  if (const auto dot = rest.find('.'); dot != std::string_view::npos) rest = rest.substr(0, dot);
  return rest;
}

int VehicleParameter::component() const {
  const std::string_view s = section();
  if (s.empty()) return -1;
  const std::string_view rest = name.substr(s.size() + 1);
  const auto dot = rest.find('.');
  if (dot == std::string_view::npos) return -1;
  const std::string_view axis = rest.substr(dot + 1);
  return axis == "x" ? 0 : axis == "y" ? 1 : 2;
}

const std::vector<VehicleParameter>& vehicle_parameters() {
  static const std::vector<VehicleParameter> table = make_table();
  return table;
}

const VehicleParameter* find_vehicle_parameter(std::string_view name) {
  for (const auto& p : vehicle_parameters()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

namespace {
std::string fmt_count(const char* name, int n, const char* layout) {
  return std::string(name) + " must be in [4, 8] (layout " + layout + "), got " + std::to_string(n);
}

std::string must(const char* name, const char* what, double got) {
  std::ostringstream s;
  s << name << " must be " << what << ", got " << got;
  return s.str();
}
}  // namespace

std::string validate(const VehicleParams& p) {
  for (const VehicleParameter& f : vehicle_parameters()) {
    if (f.kind != VehicleParameter::Kind::kNumber) continue;
    const double v = f.get(p);
    if (!f.range.contains(v)) {
      std::ostringstream s;
      s << f.name << " must be in " << f.range.text();
      if (!f.unit.empty()) s << " " << f.unit;
      s << ", got " << v;
      return s.str();
    }
  }
  if (!p.principal_axes()) {
    // A tensor that is not positive definite has no physical body (and no inverse to integrate with).
    const Eigen::LLT<Eigen::Matrix3d> llt(p.inertia_tensor());
    if (llt.info() != Eigen::Success) {
      std::ostringstream s;
      s << "Ixy_kg_m2 with Ixz_kg_m2 and Iyz_kg_m2 must leave the inertia tensor positive definite, got [["
        << p.Ixx_kg_m2 << ", " << p.Ixy_kg_m2 << ", " << p.Ixz_kg_m2 << "], [" << p.Ixy_kg_m2 << ", " << p.Iyy_kg_m2
        << ", " << p.Iyz_kg_m2 << "], [" << p.Ixz_kg_m2 << ", " << p.Iyz_kg_m2 << ", " << p.Izz_kg_m2 << "]] kg m^2";
      return s.str();
    }
  }
  if (p.aero.rotor_aero == RotorAero::kOn && p.aero.rotor_drag_k_d != 0.0 && p.aero.rotor_drag_N_s_m_per_rad_s != 0.0) {
    // The same drag twice: the lumped coefficient at the centre of mass and k_d at the hubs.
    return must("aero.rotor_drag_N_s_m_per_rad_s", "0 when aero.rotor_drag_k_d acts (the same rotor drag, at the hubs)",
                p.aero.rotor_drag_N_s_m_per_rad_s);
  }
  if (p.motor.omega_min_rad_s >= p.motor.omega_max_rad_s) {
    return must("motor.omega_min_rad_s", "below motor.omega_max_rad_s", p.motor.omega_min_rad_s);
  }
  return validate_rotors(p);
}

std::string validate_rotors(const VehicleParams& p) {
  const int n = p.rotor_count;
  if (n < kMinRotors || n > kMaxRotors) {
    return fmt_count("rotor_count", n, to_string(p.layout));
  }
  if (p.layout != RotorLayout::kCustom && n != layout_rotor_count(p.layout)) {
    return "rotor_count must be " + std::to_string(layout_rotor_count(p.layout)) + " for layout " +
           to_string(p.layout) + ", got " + std::to_string(n);
  }
  for (int i = 0; i < n; ++i) {
    const int s = p.spin[static_cast<std::size_t>(i)];
    if (s != 1 && s != -1) {
      return "spin must be " + std::to_string(n) + " values (one per rotor of layout " + to_string(p.layout) +
             "), each +1 or -1, got " + signs_text(p.spin, n);
    }
  }
  if (p.layout == RotorLayout::kCustom) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d& r = p.rotor_positions_m[static_cast<std::size_t>(i)];
      if (!r.allFinite()) {
        return "rotors must have finite positions, got rotor " + std::to_string(i + 1) + " at [" + number_text(r.x()) +
               ", " + number_text(r.y()) + ", " + number_text(r.z()) + "] m";
      }
      for (int j = 0; j < i; ++j) {
        if ((r - p.rotor_positions_m[static_cast<std::size_t>(j)]).norm() < 1e-6) {
          return "rotors must be at distinct positions, got rotors " + std::to_string(j + 1) + " and " +
                 std::to_string(i + 1) + " both at [" + number_text(r.x()) + ", " + number_text(r.y()) + ", " +
                 number_text(r.z()) + "] m";
        }
      }
    }
  }
  if (n == 4 && p.layout != RotorLayout::kCustom) {
    const int sum = p.spin[0] + p.spin[1] + p.spin[2] + p.spin[3];
    if (sum != 0) return "spin must have two +1 and two -1 entries (sum 0), got " + signs_text(p.spin, n);
    // Adjacent rotors turning the same way make the yaw row of eq. (4) a combination of the other
    // rows (for either layout): the mixer is singular and yaw cannot be allocated.
    if (p.spin[0] != p.spin[2]) {
      return "spin must alternate around the frame (rotors 1 and 3 one way, 2 and 4 the other), got " +
             signs_text(p.spin, n);
    }
  }
  // Full row rank: each row scaled to its largest entry (k_t, k_t L and k_m differ by orders of
  // magnitude), then the rank of the 4 x N matrix.
  MixerMatrix M = mixer_matrix(p);
  for (int r = 0; r < 4; ++r) {
    const double m = M.row(r).cwiseAbs().maxCoeff();
    if (m > 0.0) M.row(r) /= m;
  }
  Eigen::FullPivLU<Eigen::MatrixXd> lu(Eigen::MatrixXd(M.transpose()));
  lu.setThreshold(1e-9);
  if (lu.rank() < 4) {
    return "spin with the rotor positions of layout " + std::string(to_string(p.layout)) +
           " leaves the mixer singular (rank " + std::to_string(lu.rank()) +
           " of 4: thrust, roll, pitch and yaw cannot all be commanded), spin " + signs_text(p.spin, n);
  }
  return {};
}

std::string validate_step(const VehicleParams& p, double period_s, int substeps) {
  if (p.motor.model != MotorModel::kFirstOrder) return {};
  const double tau = std::min(p.motor.tau_up_s, p.motor.tau_down_s);
  const double h = period_s / substeps;
  if (h <= 2.0 * tau) return {};
  std::ostringstream s;
  s << "motor time constant " << tau << " s is too short for an RK4 step of " << h << " s (plant period " << period_s
    << " s / " << substeps << " substeps): use at least " << static_cast<int>(std::ceil(period_s / (2.0 * tau)))
    << " substeps";
  return s.str();
}

const char* to_string(RotorLayout layout) {
  switch (layout) {
    case RotorLayout::kPlus: return "plus";
    case RotorLayout::kX: return "x";
    case RotorLayout::kHexPlus: return "hex_plus";
    case RotorLayout::kHexX: return "hex_x";
    case RotorLayout::kOctoPlus: return "octo_plus";
    case RotorLayout::kOctoX: return "octo_x";
    case RotorLayout::kCustom: return "custom";
  }
  return "?";
}
const char* to_string(MotorModel model) { return model == MotorModel::kIdeal ? "ideal" : "first_order"; }
const char* to_string(GyroscopicModel model) { return model == GyroscopicModel::kFull ? "full" : "simplified"; }

}  // namespace quadcosim::model
