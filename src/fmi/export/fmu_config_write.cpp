// The FMU's configuration as JSON (to_json): the keys config_from_json (fmu_config_read.cpp) reads.
#include <nlohmann/json.hpp>
#include <type_traits>

#include "fmi/export/fmu_config.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::fmi {

using nlohmann::json;

namespace {

json vec(const Eigen::Ref<const Eigen::VectorXd>& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

json timing_json(const sim::SensorTiming& t) { return {{"divider", t.divider}, {"latency_ticks", t.latency_ticks}}; }

/// The extra sensors' configurations (sensors/registry.hpp), each as its fields by name.
json extra_sensors_json(const sensors::SensorSet& set) {
  json j = json::object();
  sensors::for_each_configured(set, [&]<class Kind>(const typename Kind::Config& c) {
    json fields = json::object();
    Kind::config_fields(c, [&](const char* name, const auto& v) {
      if constexpr (std::is_same_v<std::decay_t<decltype(v)>, Eigen::Vector3d>) {
        fields[name] = vec(v);
      } else {
        fields[name] = v;
      }
    });
    j[std::string(Kind::kName)] = fields;
  });
  return j;
}

json realism_json(const sim::RealismConfig& r) {
  json faults = json::array();
  for (const auto& f : r.faults) faults.push_back({{"tick", f.tick}, {"rotor", f.rotor}, {"efficiency", f.efficiency}});
  const auto& i = r.imu;
  return {{"seed", r.seed},
          {"imu",
           {{"timing", timing_json(i.timing)},
            {"gyro_noise_density", i.gyro_noise_density},
            {"gyro_bias_random_walk", i.gyro_bias_random_walk},
            {"gyro_bias_initial", i.gyro_bias_initial},
            {"accel_noise_density", i.accel_noise_density},
            {"accel_bias_random_walk", i.accel_bias_random_walk},
            {"accel_bias_initial", i.accel_bias_initial},
            {"orientation_sigma_rad", i.orientation_sigma_rad}}},
          {"pose",
           {{"timing", timing_json(r.pose.timing)},
            {"position_sigma_m", r.pose.position_sigma_m},
            {"orientation_sigma_rad", r.pose.orientation_sigma_rad}}},
          {"velocity",
           {{"timing", timing_json(r.velocity.timing)},
            {"linear_sigma_m_s", r.velocity.linear_sigma_m_s},
            {"angular_sigma_rad_s", r.velocity.angular_sigma_rad_s}}},
          {"wind",
           {{"mean_W_m_s", vec(r.wind.mean_W_m_s)},
            {"gusts",
             {{"enabled", r.wind.gusts.enabled},
              {"w20_m_s", r.wind.gusts.w20_m_s},
              {"altitude_m", r.wind.gusts.altitude_m},
              {"airspeed_m_s", r.wind.gusts.airspeed_m_s}}}}},
          {"faults", faults},
          {"extra_sensors", extra_sensors_json(r.extra_sensors)}};
}

json vehicle_json(const model::VehicleParams& v) {
  json j = json::object();
  for (const auto& p : model::vehicle_parameters()) {
    const std::string name(p.name);
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: j[name] = p.get(v); break;
      case model::VehicleParameter::Kind::kChoice: j[name] = std::string(p.choice_of(v)); break;
      case model::VehicleParameter::Kind::kSigns: {  // one per rotor (a quadrotor's four, as always)
        json signs = json::array();
        for (int i = 0; i < v.rotor_count; ++i) signs.push_back(v.spin[static_cast<std::size_t>(i)]);
        j[name] = signs;
        break;
      }
      case model::VehicleParameter::Kind::kRotors: {
        // A custom layout's rotors as a vehicle file gives them (io/vehicle_yaml.cpp); a standard
        // layout places its rotors itself, so its configuration (and GUID) stays as it was.
        if (v.layout != model::RotorLayout::kCustom) break;
        json rotors = json::array();
        for (int i = 0; i < v.rotor_count; ++i) {
          const auto r = static_cast<std::size_t>(i);
          rotors.push_back({{"position_m", vec(v.rotor_positions_m[r])}, {"spin", v.spin[r]}});
        }
        j[name] = rotors;
        break;
      }
    }
  }
  return j;
}

const char* yaw_mode_name(trajectory::YawMode m) {
  switch (m) {
    case trajectory::YawMode::kFixed: return "fixed";
    case trajectory::YawMode::kTangent: return "tangent";
    case trajectory::YawMode::kCentre: return "centre";
  }
  return "fixed";
}

// The trajectory in the keys of the scenario's `trajectory:` section (docs/scenarios.md); a polynomial
// file as its segments, since the FMU cannot reach the file.
json trajectory_json(const trajectory::TrajectorySpec& spec) {
  const auto yaw = [](json& j, trajectory::YawMode mode, double yaw_rad) {
    j["yaw_mode"] = yaw_mode_name(mode);
    j["yaw_rad"] = yaw_rad;
  };
  const auto start = [](json& j, const Eigen::Vector2d& centre, double altitude, double start_s, double ramp_s) {
    j["centre_m"] = vec(centre);
    j["altitude_m"] = altitude;
    j["start_s"] = start_s;
    j["ramp_s"] = ramp_s;
  };
  json j = json::object();
  if (const auto* c = std::get_if<trajectory::CircleParams>(&spec)) {
    j["kind"] = "circle";
    start(j, c->centre_m, c->altitude_m, c->start_s, c->ramp_s);
    j["radius_m"] = c->radius_m;
    j["period_s"] = c->period_s;
    j["direction"] = c->clockwise ? "cw" : "ccw";
    j["phase_rad"] = c->phase_rad;
    yaw(j, c->yaw_mode, c->yaw_rad);
  } else if (const auto* l = std::get_if<trajectory::LissajousParams>(&spec)) {
    j["kind"] = "lissajous";
    start(j, l->centre_m, l->altitude_m, l->start_s, l->ramp_s);
    j["amplitude_m"] = vec(l->amplitude_m);
    j["period_s"] = vec(l->period_s);
    j["phase_rad"] = vec(l->phase_rad);
    yaw(j, l->yaw_mode, l->yaw_rad);
  } else if (const auto* f = std::get_if<trajectory::Figure8Params>(&spec)) {
    j["kind"] = "figure8";
    start(j, f->centre_m, f->altitude_m, f->start_s, f->ramp_s);
    j["amplitude_m"] = vec(f->amplitude_m);
    j["period_s"] = f->period_s;
    yaw(j, f->yaw_mode, f->yaw_rad);
  } else if (const auto* w = std::get_if<trajectory::WaypointsSpec>(&spec)) {
    j["kind"] = "waypoints";
    j["method"] = trajectory::method_name(w->method);
    json points = json::array();
    for (const trajectory::Waypoint& p : w->points) {
      json point = {{"t_s", p.t_s}, {"position_m", vec(p.p_W)}};
      if (p.yaw_rad) point["yaw_rad"] = *p.yaw_rad;
      points.push_back(point);
    }
    j["points"] = points;
  } else {
    const auto& poly = std::get<trajectory::PiecewisePolynomial>(spec);
    j["kind"] = "polynomial";
    j["label"] = poly.label();
    j["start_s"] = poly.start_s();
    json segments = json::array();
    for (const trajectory::PiecewisePolynomial::Segment& seg : poly.segments()) {
      segments.push_back({{"duration_s", seg.duration_s},
                          {"x", vec(seg.c.row(0).transpose())},
                          {"y", vec(seg.c.row(1).transpose())},
                          {"z", vec(seg.c.row(2).transpose())},
                          {"yaw", vec(seg.c.row(3).transpose())}});
    }
    j["segments"] = segments;
  }
  return j;
}

}  // namespace

std::string to_json(const FmuConfig& c) {
  json params = json::object();
  for (const auto& s : c.controller_parameters) {
    if (const double* d = std::get_if<double>(&s.value)) {
      params[s.name] = *d;
    } else {
      params[s.name] = std::get<std::string>(s.value);
    }
  }
  const Eigen::Vector4d q(c.initial.q_WB.w(), c.initial.q_WB.x(), c.initial.q_WB.y(), c.initial.q_WB.z());
  json j = {
      {"kind", to_string(c.kind)},
      {"fmi_version", c.fmi_version == FmiVersion::k2 ? "2.0" : "3.0"},
      {"guid", c.guid},
      {"plant_period_ns", c.plant_period_ns},
      {"substeps", c.substeps},
      {"controller_divider", c.controller_divider},
      {"vehicle", vehicle_json(c.vehicle)},
      {"initial",
       {{"p_W", vec(c.initial.p_W)},
        {"v_W", vec(c.initial.v_W)},
        {"q_WB", vec(q)},
        {"w_B", vec(c.initial.w_B)},
        {"omega", vec(c.initial.omega_rad_s)}}},
      {"realism", realism_json(c.realism)},
      {"realism_namespace", c.realism_namespace},
      {"controller", {{"type", c.controller_type}, {"parameters", params}}},
      {"setpoint",
       {{"mode", control::to_string(c.setpoint.mode)},
        {"p_des_W", vec(c.setpoint.p_des_W)},
        {"roll_des_rad", c.setpoint.roll_des_rad},
        {"pitch_des_rad", c.setpoint.pitch_des_rad},
        {"yaw_des_rad", c.setpoint.yaw_des_rad}}},
  };
  if (c.stop_time_s) j["stop_time_s"] = *c.stop_time_s;
  // Only with one: the configuration (and so the GUID) of an FMU without a trajectory stays as it was.
  if (c.trajectory) j["trajectory"] = trajectory_json(*c.trajectory);
  return j.dump(2) + "\n";
}

}  // namespace quadcosim::fmi
