#include "model/vehicle_params.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace quadcosim::model {

double VehicleParams::hover_omega_rad_s() const {
  return std::sqrt(mass_kg * gravity_m_s2 / (4.0 * kt_N_per_rad2_s2));
}

namespace {
bool positive_finite(double v) { return std::isfinite(v) && v > 0.0; }

std::string must(const char* name, const char* what, double got) {
  std::ostringstream s;
  s << name << " must be " << what << ", got " << got;
  return s.str();
}
}  // namespace

std::string validate(const VehicleParams& p) {
  const struct {
    const char* name;
    double value;
  } positives[] = {
      {"mass_kg", p.mass_kg},
      {"gravity_m_s2", p.gravity_m_s2},
      {"Ixx_kg_m2", p.Ixx_kg_m2},
      {"Iyy_kg_m2", p.Iyy_kg_m2},
      {"Izz_kg_m2", p.Izz_kg_m2},
      {"arm_length_m", p.arm_length_m},
      {"kt_N_per_rad2_s2", p.kt_N_per_rad2_s2},
      {"km_Nm_per_rad2_s2", p.km_Nm_per_rad2_s2},
      {"motor.tau_up_s", p.motor.tau_up_s},
      {"motor.tau_down_s", p.motor.tau_down_s},
      {"motor.omega_max_rad_s", p.motor.omega_max_rad_s},
  };
  for (const auto& f : positives) {
    if (!positive_finite(f.value)) return must(f.name, "a finite number > 0", f.value);
  }
  if (!std::isfinite(p.motor.omega_min_rad_s) || p.motor.omega_min_rad_s < 0.0) {
    return must("motor.omega_min_rad_s", "a finite number >= 0", p.motor.omega_min_rad_s);
  }
  if (p.motor.omega_min_rad_s >= p.motor.omega_max_rad_s) {
    return must("motor.omega_min_rad_s", "below motor.omega_max_rad_s", p.motor.omega_min_rad_s);
  }
  for (int s : p.spin) {
    if (s != 1 && s != -1) return must("spin", "a list of four values, each +1 or -1", s);
  }
  int sum = p.spin[0] + p.spin[1] + p.spin[2] + p.spin[3];
  if (sum != 0) return must("spin", "two +1 and two -1 entries (sum 0)", sum);
  // Adjacent rotors turning the same way make the yaw row of eq. (4) a combination of the other
  // rows (for either layout): the mixer is singular and yaw cannot be allocated.
  if (p.spin[0] != p.spin[2]) {
    std::ostringstream s;
    s << "spin must alternate around the frame (rotors 1 and 3 one way, 2 and 4 the other), got ["
      << p.spin[0] << ", " << p.spin[1] << ", " << p.spin[2] << ", " << p.spin[3] << "]";
    return s.str();
  }
  return validate(p.aero);
}

std::string validate_step(const VehicleParams& p, double period_s, int substeps) {
  if (p.motor.model != MotorModel::kFirstOrder) return {};
  const double tau = std::min(p.motor.tau_up_s, p.motor.tau_down_s);
  const double h = period_s / substeps;
  if (h <= 2.0 * tau) return {};
  std::ostringstream s;
  s << "motor time constant " << tau << " s is too short for an RK4 step of " << h
    << " s (plant period " << period_s << " s / " << substeps << " substeps): use at least "
    << static_cast<int>(std::ceil(period_s / (2.0 * tau))) << " substeps";
  return s.str();
}

const char* to_string(RotorLayout layout) { return layout == RotorLayout::kPlus ? "plus" : "x"; }
const char* to_string(MotorModel model) {
  return model == MotorModel::kIdeal ? "ideal" : "first_order";
}
const char* to_string(GyroscopicModel model) {
  return model == GyroscopicModel::kFull ? "full" : "simplified";
}

}  // namespace quadcosim::model
