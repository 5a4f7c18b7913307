#include "sitl/px4.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "model/mixer.hpp"
#include "sitl/frames.hpp"

namespace quadcosim::sitl::px4 {

namespace {

std::array<float, 3> as_floats(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

// The standard atmosphere's troposphere: temperature [degC] at `altitude_m` above mean sea level.
double isa_temperature_c(double altitude_m) { return 15.0 - 0.0065 * altitude_m; }

std::int32_t deg_e7(double rad) {
  return static_cast<std::int32_t>(std::llround(rad * 180.0 / std::numbers::pi * 1e7));
}

std::int16_t cm_s(double v) {
  return static_cast<std::int16_t>(std::clamp(std::llround(v * 100.0), -32767LL, 32767LL));
}

std::uint16_t cm(double sigma_m) {
  return static_cast<std::uint16_t>(std::clamp(std::llround(sigma_m * 100.0), 1LL, 65534LL));
}

}  // namespace

std::optional<ModeNumbers> mode_numbers(const std::string& name) {
  // PX4's custom main modes (px4_custom_mode.h): 1 MANUAL, 2 ALTCTL, 3 POSCTL, 4 AUTO, 5 ACRO,
  // 6 OFFBOARD, 7 STABILIZED; AUTO's sub modes 2 TAKEOFF, 3 LOITER, 4 MISSION, 5 RTL, 6 LAND.
  static const std::pair<const char*, ModeNumbers> kModes[] = {
      {"manual", {1, 0}},   {"altctl", {2, 0}},     {"posctl", {3, 0}},  {"acro", {5, 0}},
      {"offboard", {6, 0}}, {"stabilized", {7, 0}}, {"takeoff", {4, 2}}, {"loiter", {4, 3}},
      {"mission", {4, 4}},  {"rtl", {4, 5}},        {"land", {4, 6}}};
  for (const auto& [n, m] : kModes) {
    if (name == n) return m;
  }
  return std::nullopt;
}

const char* mode_names() {
  return "manual, altctl, posctl, acro, offboard, stabilized, takeoff, loiter, mission, rtl, land";
}

mavlink::HilSensor hil_sensor(const control::Observation& obs, std::uint64_t time_usec, bool mag, bool baro) {
  mavlink::HilSensor m;
  m.time_usec = time_usec;
  m.acc_m_s2 = as_floats(flu_to_frd(obs.specific_force_B));
  m.gyro_rad_s = as_floats(flu_to_frd(obs.w_B));
  m.fields_updated = kAccel | kGyro;
  if (const auto* r = obs.sensors.get<sensors::MagnetometerKind>(); mag && r && r->stamp_ns >= 0) {
    m.mag_gauss = as_floats(flu_to_frd(r->sample.field_B_T) * 1e4);  // 1 gauss = 1e-4 T
    m.fields_updated |= kMag;
  }
  if (const auto* r = obs.sensors.get<sensors::BarometerKind>(); baro && r && r->stamp_ns >= 0) {
    m.abs_pressure_hpa = static_cast<float>(r->sample.pressure_Pa / 100.0);
    m.pressure_alt_m = static_cast<float>(r->sample.altitude_m);
    m.temperature_c = static_cast<float>(isa_temperature_c(r->sample.altitude_m));
    m.fields_updated |= kBaro;
  }
  m.id = 0;
  return m;
}

mavlink::HilGps hil_gps(const sensors::GnssSample& s, std::uint64_t utc) {
  mavlink::HilGps g;
  g.time_usec = utc;
  g.cog = 65535;
  if (!s.fix || !std::isfinite(s.position.latitude_rad)) {
    g.fix_type = 1;  // no fix
    g.eph = g.epv = 65535;
    return g;
  }
  g.lat = deg_e7(s.position.latitude_rad);
  g.lon = deg_e7(s.position.longitude_rad);
  g.alt = static_cast<std::int32_t>(std::llround(s.position.height_m * 1000.0));
  const Eigen::Vector3d& var = s.position_variance_enu;
  g.eph = cm(std::sqrt(std::max(0.0, 0.5 * (var.x() + var.y()))));
  g.epv = cm(std::sqrt(std::max(0.0, var.z())));
  const Eigen::Vector3d v_ned = enu_to_ned(s.velocity_W);
  g.vn = cm_s(v_ned.x());
  g.ve = cm_s(v_ned.y());
  g.vd = cm_s(v_ned.z());
  const double speed = std::hypot(v_ned.x(), v_ned.y());
  g.vel = static_cast<std::uint16_t>(std::min(std::llround(speed * 100.0), 65534LL));
  if (speed >= 0.01) {
    double cog = std::atan2(v_ned.y(), v_ned.x()) * 180.0 / std::numbers::pi;
    if (cog < 0) cog += 360.0;
    g.cog = static_cast<std::uint16_t>(std::llround(cog * 100.0) % 36000);
  }
  g.fix_type = 3;
  g.satellites_visible = 10;
  return g;
}

std::uint64_t utc_usec(double t_s) {
  constexpr std::uint64_t k2026 = 1767225600ULL * 1000000ULL;  // 2026-01-01T00:00:00Z
  return k2026 + static_cast<std::uint64_t>(std::llround(t_s * 1e6));
}

Eigen::Vector4d omega_from_controls(const MotorMap& map, const std::array<float, 16>& controls) {
  Eigen::Vector4d w;
  for (int i = 0; i < 4; ++i) {
    const float u = controls[static_cast<std::size_t>(map.channel_of_rotor[i])];
    w[i] = std::isfinite(u) ? std::clamp(static_cast<double>(u), 0.0, 1.0) * map.omega_max_rad_s : 0.0;
  }
  return w;
}

std::vector<std::pair<std::string, std::string>> vehicle_params(const model::VehicleParams& v, const MotorMap& map) {
  std::vector<std::pair<std::string, std::string>> p;
  p.emplace_back("CA_ROTOR_COUNT", "4");
  const double ratio = v.km_Nm_per_rad2_s2 / v.kt_N_per_rad2_s2;
  for (int out = 0; out < 4; ++out) {
    int rotor = 0;
    while (map.channel_of_rotor[rotor] != out) ++rotor;
    const Eigen::Vector3d r_frd = flu_to_frd(model::rotor_position_B(v, rotor));
    const std::string n = "CA_ROTOR" + std::to_string(out) + "_";
    // PX4 keeps a PX4_PARAM_ value equal to the default of that moment (0 here) as not set, and the
    // airframe's default (10016's +-0.1515 m) then wins: an exact 0 is written as 1 um.
    auto position = [](double m) { return std::abs(m) < 1e-9 ? std::string("0.000001") : fmt::format("{:.6g}", m); };
    p.emplace_back(n + "PX", position(r_frd.x()));
    p.emplace_back(n + "PY", position(r_frd.y()));
    // spin +1 turns clockwise seen from above; PX4's KM > 0 is a counter-clockwise rotor.
    p.emplace_back(n + "KM", fmt::format("{:.6g}", -v.spin[static_cast<std::size_t>(rotor)] * ratio));
  }
  p.emplace_back("THR_MDL_FAC", "1");
  const double hover =
      v.mass_kg * v.gravity_m_s2 / (4.0 * v.kt_N_per_rad2_s2 * v.motor.omega_max_rad_s * v.motor.omega_max_rad_s);
  p.emplace_back("MPC_THR_HOVER", fmt::format("{:.4f}", std::clamp(hover, 0.1, 0.8)));
  return p;
}

std::vector<std::pair<std::string, std::string>> read_param_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("params: cannot read '" + path + "'");
  std::vector<std::pair<std::string, std::string>> out;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    std::string name, value, extra;
    if (!(words >> name)) continue;
    const bool name_ok = std::all_of(
        name.begin(), name.end(), [](char c) { return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'; });
    char* end = nullptr;
    const bool read = static_cast<bool>(words >> value);
    if (read) std::strtod(value.c_str(), &end);
    if (!name_ok || !read || end == value.c_str() || *end != '\0' || (words >> extra)) {
      throw std::invalid_argument(fmt::format(
          "params: {}:{}: expected NAME VALUE (a parameter in capitals and a number), got '{}'", path, number, line));
    }
    out.emplace_back(name, value);
  }
  return out;
}

}  // namespace quadcosim::sitl::px4
