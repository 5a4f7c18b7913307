#include "control/parameters.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

namespace quadcosim::control {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kBig = 1e9;

// One numeric parameter bound to a double inside ControllerConfig.
#define QC_NUMBER(NAME, UNIT, MIN, MAX, DESIGN, FIELD, DESC)                                                     \
  ParameterSpec {                                                                                                \
    NAME, UNIT, DESC, MIN, MAX, {}, DESIGN, [](const ControllerConfig& c) -> ParameterValue { return c.FIELD; }, \
        [](ControllerConfig& c, const ParameterValue& v) { c.FIELD = std::get<double>(v); }                      \
  }

std::vector<ParameterSpec> make_table() {
  std::vector<ParameterSpec> t = {
      ParameterSpec{"mode",
                    "choice",
                    "attitude: roll/pitch/yaw setpoints + altitude hold; position: x/y/z/yaw",
                    0,
                    0,
                    {"attitude", "position"},
                    false,
                    [](const ControllerConfig& c) -> ParameterValue { return to_string(c.setpoint.mode); },
                    [](ControllerConfig& c, const ParameterValue& v) {
                      c.setpoint.mode = std::get<std::string>(v) == "position" ? Mode::kPosition : Mode::kAttitude;
                    }},
      QC_NUMBER("x_des", "m", -1e5, 1e5, false, setpoint.p_des_W.x(), "desired x (east), position mode"),
      QC_NUMBER("y_des", "m", -1e5, 1e5, false, setpoint.p_des_W.y(), "desired y (north), position mode"),
      QC_NUMBER("z_des", "m", -1e3, 1e5, false, setpoint.p_des_W.z(), "desired altitude z (up)"),
      QC_NUMBER("roll_des", "rad", -1.5, 1.5, false, setpoint.roll_des_rad, "desired roll, attitude mode"),
      QC_NUMBER("pitch_des", "rad", -1.5, 1.5, false, setpoint.pitch_des_rad, "desired pitch, attitude mode"),
      QC_NUMBER("yaw_des", "rad", -2 * kPi, 2 * kPi, false, setpoint.yaw_des_rad, "desired yaw"),
      QC_NUMBER("altitude.kp", "N/m", 0, kBig, true, params.altitude.kp, "altitude P gain K_p,z, eq. (12)"),
      QC_NUMBER("altitude.kd", "N s/m", 0, kBig, true, params.altitude.kd, "altitude D gain K_d,z, eq. (12)"),
      QC_NUMBER("altitude.min_cos_tilt", "", 0.05, 1, true, params.altitude.min_cos_tilt,
                "floor on cos(roll) cos(pitch) in eq. (13)"),
      QC_NUMBER("lqr.roll.q_angle", "1/rad^2", 0, kBig, true, params.roll.q_angle, "roll LQR weight on angle error"),
      QC_NUMBER("lqr.roll.q_rate", "s^2/rad^2", 0, kBig, true, params.roll.q_rate, "roll LQR weight on rate"),
      QC_NUMBER("lqr.roll.r", "1/(N m)^2", 1e-12, kBig, true, params.roll.r, "roll LQR weight on torque"),
      QC_NUMBER("lqr.pitch.q_angle", "1/rad^2", 0, kBig, true, params.pitch.q_angle, "pitch LQR weight on angle error"),
      QC_NUMBER("lqr.pitch.q_rate", "s^2/rad^2", 0, kBig, true, params.pitch.q_rate, "pitch LQR weight on rate"),
      QC_NUMBER("lqr.pitch.r", "1/(N m)^2", 1e-12, kBig, true, params.pitch.r, "pitch LQR weight on torque"),
      QC_NUMBER("lqr.yaw.q_angle", "1/rad^2", 0, kBig, true, params.yaw.q_angle, "yaw LQR weight on angle error"),
      QC_NUMBER("lqr.yaw.q_rate", "s^2/rad^2", 0, kBig, true, params.yaw.q_rate, "yaw LQR weight on rate"),
      QC_NUMBER("lqr.yaw.r", "1/(N m)^2", 1e-12, kBig, true, params.yaw.r, "yaw LQR weight on torque"),
      QC_NUMBER("position.kp", "1/s^2", 0, kBig, true, params.position.kp, "position P gain"),
      QC_NUMBER("position.ki", "1/s^3", 0, kBig, true, params.position.ki, "position I gain"),
      QC_NUMBER("position.kd", "1/s", 0, kBig, true, params.position.kd, "position D gain (on velocity)"),
      QC_NUMBER("position.integral_limit", "m s", 0, kBig, true, params.position.integral_limit,
                "anti-windup bound on each axis's error integral"),
      QC_NUMBER("position.max_tilt", "rad", 0.01, 1.2, true, params.position.max_tilt_rad,
                "tilt limit on the roll/pitch the position loop commands"),
      QC_NUMBER("stale_limit", "s", 1e-4, 1e4, true, params.stale_limit_s,
                "sensor data older than this triggers the safety command (Algorithm 1)"),
      ParameterSpec{"safety_mode",
                    "choice",
                    "safety command: stop (omega_min) or hover (hover speed)",
                    0,
                    0,
                    {"stop", "hover"},
                    true,
                    [](const ControllerConfig& c) -> ParameterValue { return to_string(c.params.safety); },
                    [](ControllerConfig& c, const ParameterValue& v) {
                      c.params.safety = std::get<std::string>(v) == "hover" ? SafetyMode::kHover : SafetyMode::kStop;
                    }},
  };
  return t;
}
#undef QC_NUMBER

}  // namespace

const std::vector<ParameterSpec>& controller_parameters() {
  static const std::vector<ParameterSpec> table = make_table();
  return table;
}

const ParameterSpec* find_parameter(std::string_view name) {
  for (const auto& p : controller_parameters()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::string to_string(const ParameterValue& value) {
  if (const auto* s = std::get_if<std::string>(&value)) return *s;
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, std::get<double>(value));  // shortest round trip
  return std::string(buf, r.ptr);
}

std::string set_parameter(ControllerConfig& config, std::string_view name, const ParameterValue& value) {
  const ParameterSpec* spec = find_parameter(name);
  if (!spec) return "unknown parameter '" + std::string(name) + "'";
  std::ostringstream err;
  if (spec->is_choice()) {
    const auto* s = std::get_if<std::string>(&value);
    bool ok = false;
    if (s) {
      for (auto c : spec->choices) ok = ok || c == *s;
    }
    if (!ok) {
      err << name << " must be one of";
      for (auto c : spec->choices) err << " '" << c << "'";
      err << ", got '" << to_string(value) << "'";
      return err.str();
    }
  } else {
    const auto* d = std::get_if<double>(&value);
    if (!d) return std::string(name) + " must be a number, got '" + to_string(value) + "'";
    if (!std::isfinite(*d) || *d < spec->min || *d > spec->max) {
      err << name << " must be in [" << spec->min << ", " << spec->max << "]";
      if (!spec->unit.empty()) err << " " << spec->unit;
      err << ", got " << to_string(value);
      return err.str();
    }
  }
  spec->set(config, value);
  return {};
}

std::optional<ParameterValue> get_parameter(const ControllerConfig& config, std::string_view name) {
  const ParameterSpec* spec = find_parameter(name);
  if (!spec) return std::nullopt;
  return spec->get(config);
}

}  // namespace quadcosim::control
