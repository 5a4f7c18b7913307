#include "fmi/export/fmu_config.hpp"

#include <array>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <type_traits>

#include "controllers/registry.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::fmi {

using nlohmann::json;

std::string_view to_string(FmuKind kind) { return kind == FmuKind::kPlant ? "plant" : "controller"; }

std::string_view model_identifier(FmuKind kind) {
  return kind == FmuKind::kPlant ? "quadcosim_plant" : "quadcosim_controller";
}

// ---- JSON ---------------------------------------------------------------------------------------

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
      case model::VehicleParameter::Kind::kSigns: j[name] = v.spin; break;
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

// Reading: every accessor names the key path it was looking at.
class Reader {
 public:
  Reader(const json& j, std::string path) : j_(j), path_(std::move(path)) {}

  Reader at(const std::string& key) const {
    if (!j_.is_object() || !j_.contains(key)) fail(key, "missing");
    return Reader(j_.at(key), join(key)).with_source(source_);
  }
  bool has(const std::string& key) const { return j_.is_object() && j_.contains(key); }
  double number() const {
    if (!j_.is_number()) fail("", "not a number");
    return j_.get<double>();
  }
  template <class I>
  I integer() const {
    if (!j_.is_number_integer()) fail("", "not an integer");
    // Through the widest type of the right signedness, then range-checked.
    if constexpr (std::is_signed_v<I>) {
      const auto v = j_.get<std::int64_t>();
      if (v < std::numeric_limits<I>::min() || v > std::numeric_limits<I>::max()) fail("", "out of range");
      return static_cast<I>(v);
    } else {
      if (j_.is_number_unsigned()) {
        const auto v = j_.get<std::uint64_t>();
        if (v > std::numeric_limits<I>::max()) fail("", "out of range");
        return static_cast<I>(v);
      }
      const auto v = j_.get<std::int64_t>();
      if (v < 0) fail("", "negative");
      return static_cast<I>(v);
    }
  }
  bool boolean() const {
    if (!j_.is_boolean()) fail("", "not a boolean");
    return j_.get<bool>();
  }
  std::string text() const {
    if (!j_.is_string()) fail("", "not a string");
    return j_.get<std::string>();
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vector() const {
    if (!j_.is_array() || j_.size() != N) fail("", "not an array of " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = Reader(j_[static_cast<std::size_t>(i)], path_).number();
    return v;
  }
  const json& raw() const { return j_; }
  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw FmuError(source_ + ": '" + join(key) + "' " + what);
  }
  Reader with_source(const std::string& s) const {
    Reader r = *this;
    r.source_ = s;
    return r;
  }

 private:
  std::string join(const std::string& key) const {
    if (key.empty()) return path_;
    return path_.empty() ? key : path_ + "." + key;
  }
  const json& j_;
  std::string path_;
  std::string source_;
};

sim::SensorTiming read_timing(const Reader& r) {
  return {r.at("divider").integer<int>(), r.at("latency_ticks").integer<int>()};
}

model::VehicleParams read_vehicle(const Reader& r) {
  model::VehicleParams v;
  for (const auto& p : model::vehicle_parameters()) {
    const Reader e = r.at(std::string(p.name));
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: p.ref(v) = e.number(); break;
      case model::VehicleParameter::Kind::kChoice: {
        const std::string c = e.text();
        bool known = false;
        for (auto choice : p.choices) known = known || choice == c;
        if (!known) e.fail("", "is '" + c + "', not one of the choices");
        p.set_choice(v, c);
        break;
      }
      case model::VehicleParameter::Kind::kSigns: {
        const Eigen::Vector4d s = e.vector<4>();
        for (int i = 0; i < 4; ++i) {
          if (s[i] != 1.0 && s[i] != -1.0) e.fail("", "has an entry that is neither 1 nor -1");
          v.spin[static_cast<std::size_t>(i)] = static_cast<int>(s[i]);
        }
        break;
      }
    }
  }
  return v;
}

trajectory::YawMode read_yaw_mode(const Reader& r, bool centre_allowed) {
  const std::string m = r.text();
  if (m == "fixed") return trajectory::YawMode::kFixed;
  if (m == "tangent") return trajectory::YawMode::kTangent;
  if (m == "centre" && centre_allowed) return trajectory::YawMode::kCentre;
  r.fail("", "is '" + m + "', not " + (centre_allowed ? "fixed, tangent or centre" : "fixed or tangent"));
}

trajectory::TrajectorySpec read_trajectory(const Reader& r) {
  const std::string kind = r.at("kind").text();
  const auto start = [&r](Eigen::Vector2d& centre, double& altitude, double& start_s, double& ramp_s) {
    centre = r.at("centre_m").vector<2>();
    altitude = r.at("altitude_m").number();
    start_s = r.at("start_s").number();
    ramp_s = r.at("ramp_s").number();
  };
  if (kind == "circle") {
    trajectory::CircleParams c;
    start(c.centre_m, c.altitude_m, c.start_s, c.ramp_s);
    c.radius_m = r.at("radius_m").number();
    c.period_s = r.at("period_s").number();
    const std::string direction = r.at("direction").text();
    if (direction != "ccw" && direction != "cw") r.at("direction").fail("", "is '" + direction + "', not ccw or cw");
    c.clockwise = direction == "cw";
    c.phase_rad = r.at("phase_rad").number();
    c.yaw_mode = read_yaw_mode(r.at("yaw_mode"), true);
    c.yaw_rad = r.at("yaw_rad").number();
    return c;
  }
  if (kind == "lissajous") {
    trajectory::LissajousParams l;
    start(l.centre_m, l.altitude_m, l.start_s, l.ramp_s);
    l.amplitude_m = r.at("amplitude_m").vector<2>();
    l.period_s = r.at("period_s").vector<2>();
    l.phase_rad = r.at("phase_rad").vector<2>();
    l.yaw_mode = read_yaw_mode(r.at("yaw_mode"), false);
    l.yaw_rad = r.at("yaw_rad").number();
    return l;
  }
  if (kind == "figure8") {
    trajectory::Figure8Params f;
    start(f.centre_m, f.altitude_m, f.start_s, f.ramp_s);
    f.amplitude_m = r.at("amplitude_m").vector<2>();
    f.period_s = r.at("period_s").number();
    f.yaw_mode = read_yaw_mode(r.at("yaw_mode"), false);
    f.yaw_rad = r.at("yaw_rad").number();
    return f;
  }
  if (kind == "waypoints") {
    trajectory::WaypointsSpec w;
    const std::string method = r.at("method").text();
    if (method != "min_snap" && method != "min_jerk") {
      r.at("method").fail("", "is '" + method + "', not min_snap or min_jerk");
    }
    w.method = method == "min_snap" ? trajectory::WaypointMethod::kMinSnap : trajectory::WaypointMethod::kMinJerk;
    const Reader points = r.at("points");
    if (!points.raw().is_array()) points.fail("", "not an array");
    for (std::size_t i = 0; i < points.raw().size(); ++i) {
      const Reader p = Reader(points.raw()[i], points.path() + "[" + std::to_string(i) + "]").with_source(r.source());
      trajectory::Waypoint point;
      point.t_s = p.at("t_s").number();
      point.p_W = p.at("position_m").vector<3>();
      if (p.has("yaw_rad")) point.yaw_rad = p.at("yaw_rad").number();
      w.points.push_back(point);
    }
    return w;
  }
  if (kind == "polynomial") {
    const Reader segments = r.at("segments");
    if (!segments.raw().is_array()) segments.fail("", "not an array");
    std::vector<trajectory::PiecewisePolynomial::Segment> out;
    for (std::size_t i = 0; i < segments.raw().size(); ++i) {
      const Reader s =
          Reader(segments.raw()[i], segments.path() + "[" + std::to_string(i) + "]").with_source(r.source());
      trajectory::PiecewisePolynomial::Segment seg;
      seg.duration_s = s.at("duration_s").number();
      seg.c.row(0) = s.at("x").vector<8>().transpose();
      seg.c.row(1) = s.at("y").vector<8>().transpose();
      seg.c.row(2) = s.at("z").vector<8>().transpose();
      seg.c.row(3) = s.at("yaw").vector<8>().transpose();
      out.push_back(seg);
    }
    try {
      return trajectory::PiecewisePolynomial(std::move(out), r.at("start_s").number(), r.at("label").text());
    } catch (const std::invalid_argument& e) {
      r.fail("", std::string("is not a valid polynomial: ") + e.what());
    }
  }
  r.at("kind").fail("", "is '" + kind + "', not circle, lissajous, figure8, waypoints or polynomial");
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

FmuConfig config_from_json(std::string_view text, const std::string& source) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw FmuError(source + ": not JSON (" + e.what() + ")");
  }
  const Reader r = Reader(j, "").with_source(source);
  FmuConfig c;
  const std::string kind = r.at("kind").text();
  if (kind != "plant" && kind != "controller") r.at("kind").fail("", "is '" + kind + "', not plant or controller");
  c.kind = kind == "plant" ? FmuKind::kPlant : FmuKind::kController;
  const std::string version = r.at("fmi_version").text();
  if (version != "2.0" && version != "3.0") r.at("fmi_version").fail("", "is '" + version + "', not 2.0 or 3.0");
  c.fmi_version = version == "2.0" ? FmiVersion::k2 : FmiVersion::k3;
  c.guid = r.at("guid").text();
  c.plant_period_ns = r.at("plant_period_ns").integer<std::int64_t>();
  if (c.plant_period_ns <= 0) r.at("plant_period_ns").fail("", "must be positive");
  c.substeps = r.at("substeps").integer<int>();
  if (c.substeps <= 0) r.at("substeps").fail("", "must be positive");
  c.controller_divider = r.at("controller_divider").integer<int>();
  if (c.controller_divider <= 0) r.at("controller_divider").fail("", "must be positive");
  if (r.has("stop_time_s")) c.stop_time_s = r.at("stop_time_s").number();

  c.vehicle = read_vehicle(r.at("vehicle"));
  const Reader init = r.at("initial");
  c.initial.p_W = init.at("p_W").vector<3>();
  c.initial.v_W = init.at("v_W").vector<3>();
  const Eigen::Vector4d q = init.at("q_WB").vector<4>();
  c.initial.q_WB = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  c.initial.w_B = init.at("w_B").vector<3>();
  c.initial.omega_rad_s = init.at("omega").vector<4>();

  const Reader re = r.at("realism");
  auto& m = c.realism;
  m.seed = re.at("seed").integer<std::uint64_t>();
  const Reader imu = re.at("imu");
  m.imu.timing = read_timing(imu.at("timing"));
  m.imu.gyro_noise_density = imu.at("gyro_noise_density").number();
  m.imu.gyro_bias_random_walk = imu.at("gyro_bias_random_walk").number();
  m.imu.gyro_bias_initial = imu.at("gyro_bias_initial").number();
  m.imu.accel_noise_density = imu.at("accel_noise_density").number();
  m.imu.accel_bias_random_walk = imu.at("accel_bias_random_walk").number();
  m.imu.accel_bias_initial = imu.at("accel_bias_initial").number();
  m.imu.orientation_sigma_rad = imu.at("orientation_sigma_rad").number();
  const Reader pose = re.at("pose");
  m.pose.timing = read_timing(pose.at("timing"));
  m.pose.position_sigma_m = pose.at("position_sigma_m").number();
  m.pose.orientation_sigma_rad = pose.at("orientation_sigma_rad").number();
  const Reader vel = re.at("velocity");
  m.velocity.timing = read_timing(vel.at("timing"));
  m.velocity.linear_sigma_m_s = vel.at("linear_sigma_m_s").number();
  m.velocity.angular_sigma_rad_s = vel.at("angular_sigma_rad_s").number();
  for (const sim::SensorTiming* t : {&m.imu.timing, &m.pose.timing, &m.velocity.timing}) {
    if (t->divider < 1 || t->latency_ticks < 0) re.fail("", "has a sensor divider below 1 or a negative latency");
  }
  const Reader wind = re.at("wind");
  m.wind.mean_W_m_s = wind.at("mean_W_m_s").vector<3>();
  const Reader gusts = wind.at("gusts");
  m.wind.gusts.enabled = gusts.at("enabled").boolean();
  m.wind.gusts.w20_m_s = gusts.at("w20_m_s").number();
  m.wind.gusts.altitude_m = gusts.at("altitude_m").number();
  m.wind.gusts.airspeed_m_s = gusts.at("airspeed_m_s").number();
  const Reader faults = re.at("faults");
  if (!faults.raw().is_array()) faults.fail("", "not an array");
  for (std::size_t i = 0; i < faults.raw().size(); ++i) {
    const Reader f = Reader(faults.raw()[i], faults.path() + "[" + std::to_string(i) + "]").with_source(source);
    sim::RotorFault rf{f.at("tick").integer<sim::Tick>(), f.at("rotor").integer<int>(), f.at("efficiency").number()};
    if (rf.rotor < 0 || rf.rotor > 3) f.at("rotor").fail("", "must be 0..3");
    m.faults.push_back(rf);
  }
  if (re.has("extra_sensors")) {  // absent from the configurations of FMUs exported before there were any
    const Reader extra = re.at("extra_sensors");
    sensors::for_each_kind([&]<class Kind>() {
      if (!extra.has(std::string(Kind::kName))) return;
      const Reader fields = extra.at(std::string(Kind::kName));
      typename Kind::Config config;
      Kind::config_fields(config, [&](const char* name, auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
          v = fields.at(name).template vector<3>();
        } else if constexpr (std::is_same_v<T, int>) {
          v = fields.at(name).template integer<int>();
        } else {
          v = fields.at(name).number();
        }
      });
      if (config.timing.divider < 1 || config.timing.latency_ticks < 0) {
        fields.fail("", "has a sensor divider below 1 or a negative latency");
      }
      Kind::config(m.extra_sensors) = config;
    });
  }
  c.realism_namespace = r.at("realism_namespace").text();

  const Reader ctl = r.at("controller");
  c.controller_type = ctl.at("type").text();
  const Reader params = ctl.at("parameters");
  if (!params.raw().is_object()) params.fail("", "not an object");
  for (const auto& [name, value] : params.raw().items()) {
    if (value.is_number()) {
      c.controller_parameters.push_back({name, value.get<double>()});
    } else if (value.is_string()) {
      c.controller_parameters.push_back({name, value.get<std::string>()});
    } else {
      params.fail(name, "is neither a number nor a string");
    }
  }
  const Reader sp = r.at("setpoint");
  const std::string mode = sp.at("mode").text();
  if (mode != "attitude" && mode != "position") sp.at("mode").fail("", "is '" + mode + "', not attitude or position");
  c.setpoint.mode = mode == "attitude" ? control::Mode::kAttitude : control::Mode::kPosition;
  c.setpoint.p_des_W = sp.at("p_des_W").vector<3>();
  c.setpoint.roll_des_rad = sp.at("roll_des_rad").number();
  c.setpoint.pitch_des_rad = sp.at("pitch_des_rad").number();
  c.setpoint.yaw_des_rad = sp.at("yaw_des_rad").number();
  if (r.has("trajectory")) {
    const Reader t = r.at("trajectory");
    c.trajectory = read_trajectory(t);
    try {
      trajectory::make_trajectory(*c.trajectory);
    } catch (const std::invalid_argument& e) {
      t.fail("", std::string("is not a valid trajectory: ") + e.what());
    }
  }
  return c;
}

FmuConfig read_config(const std::string& directory) {
  std::string path = directory;
  if (!path.empty() && path.back() != '/') path += '/';
  path += kConfigFileName;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FmuError("cannot read the FMU's configuration " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return config_from_json(text.str(), path);
}

std::string make_guid(const FmuConfig& config) {
  FmuConfig c = config;
  c.guid.clear();
  const std::string text = to_json(c);
  // Two independent 64-bit FNV-1a hashes (different offsets) give the 128 bits.
  auto fnv = [&](std::uint64_t h) {
    for (const unsigned char ch : text) {
      h ^= ch;
      h *= 0x100000001b3ULL;
    }
    return h;
  };
  const std::uint64_t a = fnv(0xcbf29ce484222325ULL), b = fnv(0x84222325cbf29ce4ULL);
  char buf[48];
  std::snprintf(buf, sizeof buf, "{%08x-%04x-%04x-%04x-%012llx}", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xffff),
                static_cast<unsigned>(b >> 48), static_cast<unsigned long long>(b & 0xffffffffffffULL));
  return buf;
}

// ---- Variables ----------------------------------------------------------------------------------

namespace {

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
  return std::string(buf, r.ptr);
}

struct Builder {
  ModelDescription& md;

  Variable& add(std::string_view name, Causality causality, Variability variability, std::string_view unit,
                std::string description) {
    Variable v;
    v.name = std::string(name);
    v.vr = static_cast<ValueReference>(md.variables.size());
    v.causality = causality;
    v.variability = variability;
    v.unit = std::string(unit);
    v.description = std::move(description);
    md.variables.push_back(std::move(v));
    if (causality == Causality::kOutput) {
      // No direct feedthrough: outputs are computed at the end of doStep, from the inputs held over
      // the step, so a plant and a controller FMU coupled both ways form no algebraic loop.
      md.variables.back().dependencies.emplace();
      md.outputs.push_back(md.variables.size() - 1);
    }
    return md.variables.back();
  }
  void input(std::string_view name, std::string_view unit, std::string description, double start) {
    add(name, Causality::kInput, Variability::kContinuous, unit, std::move(description)).start = number_text(start);
  }
  void output(std::string_view name, Variability variability, std::string_view unit, std::string description) {
    add(name, Causality::kOutput, variability, unit, std::move(description)).initial = Initial::kCalculated;
  }
  Variable& parameter(std::string_view name, Variability variability, std::string_view unit, std::string description,
                      std::string start) {
    Variable& v = add(name, Causality::kParameter, variability, unit, std::move(description));
    v.initial = Initial::kExact;
    v.start = std::move(start);
    return v;
  }
  template <std::size_t N>
  void inputs(const std::array<std::string_view, N>& names, std::string_view unit, const std::string& what,
              const Eigen::Matrix<double, static_cast<int>(N), 1>& start) {
    for (std::size_t i = 0; i < N; ++i) input(names[i], unit, what, start[static_cast<Eigen::Index>(i)]);
  }
  template <std::size_t N>
  void outputs(const std::array<std::string_view, N>& names, Variability variability, std::string_view unit,
               const std::string& what) {
    for (auto n : names) output(n, variability, unit, what);
  }
};

Eigen::Vector4d wxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

void plant_variables(const FmuConfig& c, Builder& b) {
  b.inputs(names::kOmegaCmd, "rad/s",
           "rotor speed command, held over the step; clamped to [omega_min, omega_max]; NaN/Inf refused",
           c.initial.omega_rad_s);
  const Variability cont = Variability::kContinuous;
  b.outputs(names::kPosition, cont, "m", "position, world frame (z up)");
  b.outputs(names::kVelocity, cont, "m/s", "velocity, world frame");
  b.outputs(names::kAttitude, cont, "1", "attitude quaternion body to world, w x y z");
  b.outputs(names::kEuler, cont, "rad", "roll, pitch, yaw (Z-Y-X Euler angles of q_WB)");
  b.outputs(names::kRates, cont, "rad/s", "body angular velocity");
  b.outputs(names::kSpecificForce, cont, "m/s2", "specific force, body frame (what an accelerometer reads)");
  b.outputs(names::kRotorSpeed, cont, "rad/s", "rotor speeds reached (after the motors' lag)");
  // The extra sensors the scenario configures: each column of the newest sample, held between samples.
  sensors::for_each_configured(c.realism.extra_sensors, [&]<class Kind>(const typename Kind::Config&) {
    for (const auto& col : Kind::kColumns) {
      for (int i = 0; i < col.width; ++i) {
        b.output(names::sensor_variable(Kind::kName, col.name, col.width, i), Variability::kDiscrete, col.unit,
                 std::string(Kind::kName) + ": " + std::string(col.description) + " (the newest sample)");
      }
    }
  });

  const Variability fixed = Variability::kFixed;
  for (const auto& p : model::vehicle_parameters()) {
    if (p.kind != model::VehicleParameter::Kind::kNumber) continue;
    Variable& v = b.parameter(std::string(names::kVehiclePrefix) + std::string(p.name), fixed, p.unit,
                              std::string(p.meaning) + ", in " + p.range.text() + " (takes effect at initialisation)",
                              number_text(p.get(c.vehicle)));
    v.min = p.range.min;
    v.max = p.range.max;
  }
  const std::string pre(names::kInitialPrefix);
  const model::State& x = c.initial;
  auto initial = [&](const auto& names, std::string_view unit, const std::string& what, const auto& values) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      b.parameter(pre + std::string(names[i]), fixed, unit, "initial " + what,
                  number_text(values[static_cast<Eigen::Index>(i)]));
    }
  };
  initial(names::kPosition, "m", "position", x.p_W);
  initial(names::kVelocity, "m/s", "velocity", x.v_W);
  initial(names::kAttitude, "1", "attitude quaternion (w x y z, unit norm)", wxyz(x.q_WB));
  initial(names::kRates, "rad/s", "body angular velocity", x.w_B);
  initial(names::kRotorSpeed, "rad/s", "rotor speeds (and the command before the first one is set)", x.omega_rad_s);

  auto flag = [&](std::string_view name, bool on, std::string what) {
    b.parameter(name, fixed, "", std::move(what), on ? "true" : "false").type = VariableType::kBoolean;
  };
  const auto& r = c.realism;
  flag("realism.wind", r.wind.active(), "wind and gusts as configured act on the vehicle");
  flag("realism.rotor_faults", !r.faults.empty(), "the configured rotor faults happen at their ticks");
  const bool sensors = [&] {
    sim::RealismConfig s = r;
    s.wind = {};
    s.faults.clear();
    return s.active();
  }();
  flag("realism.sensor_noise", sensors,
       "outputs p_W, v_W, q_WB, euler, w_B, f_B are the sensors' latest samples (noise, bias, rate, latency as "
       "configured; euler from the IMU's attitude) instead of the true values; omega stays true");
  Variable& seed =
      b.parameter("realism.seed", fixed, "", "seed of every random stream (noise, gusts)", std::to_string(r.seed));
  seed.type = VariableType::kInteger;
  seed.min = 0;
  seed.max = std::numeric_limits<std::int32_t>::max();
  if (r.seed > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    throw FmuError("realism.seed " + std::to_string(r.seed) + " does not fit an FMI Integer (at most 2147483647)");
  }
}

void controller_variables(const FmuConfig& c, Builder& b) {
  const model::Quadrotor quad(c.vehicle);
  const model::Outputs y = quad.outputs(0.0, c.initial, quad.rotor_input(c.initial.omega_rad_s));
  b.inputs(names::kPosition, "m", "measured position, world frame", y.p_W);
  b.inputs(names::kVelocity, "m/s", "measured velocity, world frame", y.v_W);
  b.inputs(names::kAttitude, "1", "measured attitude quaternion body to world, w x y z", wxyz(y.q_WB));
  b.inputs(names::kRates, "rad/s", "measured body angular velocity", y.w_B);
  b.inputs(names::kSpecificForce, "m/s2", "measured specific force, body frame", y.specific_force_B);
  // The reference inputs start at the reference the FMU flies at t = 0: the setpoint, or the
  // trajectory's first point (which they are then only used for with ref.external).
  const control::Setpoint& s = c.setpoint;
  trajectory::FlatOutput start;
  start.p_W = s.p_des_W;
  start.yaw_rad = s.yaw_des_rad;
  double roll = s.roll_des_rad, pitch = s.pitch_des_rad;
  std::string used;
  if (c.trajectory) {
    try {
      start = trajectory::make_trajectory(*c.trajectory)->at(0.0);
    } catch (const std::invalid_argument& e) {
      throw FmuError(std::string("trajectory: ") + e.what());
    }
    roll = pitch = 0.0;
    used = " (used when ref.external is true; otherwise the FMU's trajectory is the reference)";
  }
  b.inputs(
      names::kRefPosition, "m",
      (c.trajectory ? std::string("reference position") : "reference position (attitude mode: only z is held)") + used,
      start.p_W);
  b.inputs(names::kRefVelocity, "m/s", "reference velocity" + used, start.v_W);
  b.inputs(names::kRefAcceleration, "m/s2", "reference acceleration" + used, start.a_W);
  const std::array<std::string_view, 3> jerk = {"ref.j_W[1]", "ref.j_W[2]", "ref.j_W[3]"};
  b.inputs(jerk, "m/s3", "reference jerk" + used, start.j_W);
  b.input(names::kRefYaw, "rad", "reference yaw" + used, start.yaw_rad);
  b.input("ref.yaw_rate", "rad/s", "reference yaw rate" + used, start.yaw_rate_rad_s);
  b.input("ref.roll", "rad", c.trajectory ? "unused (position mode)" : "roll setpoint (attitude mode)", roll);
  b.input("ref.pitch", "rad", c.trajectory ? "unused (position mode)" : "pitch setpoint (attitude mode)", pitch);
  b.outputs(names::kOmegaCmd, Variability::kDiscrete, "rad/s",
            "rotor speed command of the latest control step (0 before the first step)");

  const control::ControllerConfig cc = controllers::make_config(c.controller_type, c.vehicle);
  std::unique_ptr<control::Controller> ctl = cc.controller->clone();
  if (std::string err = ctl->set_parameters(c.controller_parameters); !err.empty()) {
    throw FmuError("controller '" + c.controller_type + "': " + err);
  }
  // What the controller tracks and its own figures, under the names a controller that decides rotor
  // speeds reports them by (control::ReportedOutputs): an importer shows its attitude setpoint, tilt
  // flag and figures as quadcosim shows the native controller's.
  for (const std::string_view name : names::kReportedAttitude) {
    b.output(name, Variability::kDiscrete, "rad",
             "attitude the latest control step tracked (Z-Y-X angles of its desired attitude; 0 before the first "
             "step)");
  }
  b.output(names::kTiltSaturated, Variability::kDiscrete, "1",
           "1 when the latest control step's tilt limit cut the attitude it asked for, else 0");
  for (const std::string& name : ctl->output_names()) {
    b.output(name, Variability::kDiscrete, "", "the controller's own figure " + name + " at the latest control step");
  }

  if (c.trajectory) {
    b.parameter(names::kRefExternal, Variability::kFixed, "",
                "false: the reference is the trajectory this FMU carries (" +
                    trajectory::make_trajectory(*c.trajectory)->describe() +
                    "), at the FMU's own time; true: the inputs ref.* are, in position mode (takes effect at "
                    "initialisation)",
                "false")
        .type = VariableType::kBoolean;
  }

  for (const control::ParameterSpec& p : ctl->parameters()) {
    const control::ParameterValue value = *ctl->get_parameter(p.name);
    const std::string name = std::string(names::kControllerPrefix) + std::string(p.name);
    if (p.is_choice()) {
      std::string choices;
      for (auto ch : p.choices) choices += (choices.empty() ? "" : ", ") + std::string(ch);
      b.parameter(name, Variability::kTunable, "", std::string(p.description) + " (one of: " + choices + ")",
                  std::get<std::string>(value))
          .type = VariableType::kString;
    } else {
      Variable& v = b.parameter(name, Variability::kTunable, p.unit, std::string(p.description),
                                number_text(std::get<double>(value)));
      v.min = p.min;
      v.max = p.max;
    }
  }
}

}  // namespace

ModelDescription describe(const FmuConfig& c) {
  ModelDescription md;
  md.version = c.fmi_version;
  md.fmi_version = c.fmi_version == FmiVersion::k2 ? "2.0" : "3.0";
  const bool plant = c.kind == FmuKind::kPlant;
  md.model_name = plant ? "quadcosim plant" : "quadcosim controller";
  md.description = plant ? "quadcosim's 6-DOF quadrotor plant (integer-tick RK4), co-simulation"
                         : "quadcosim's '" + c.controller_type + "' flight controller, co-simulation";
  md.guid = c.guid;
  md.generation_tool = "quadcosim";
  md.model_identifier = std::string(model_identifier(c.kind));
  md.can_handle_variable_step = false;
  md.can_be_instantiated_only_once_per_process = false;
  md.can_get_and_set_fmu_state = true;  // fmi2GetFMUstate/SetFMUstate/FreeFMUstate (not serialisation)
  const std::int64_t period_ns = plant ? c.plant_period_ns : c.plant_period_ns * c.controller_divider;
  md.start_time = 0.0;
  md.stop_time = c.stop_time_s;
  md.step_size = static_cast<double>(period_ns) / 1e9;

  Builder b{md};
  b.add("time", Causality::kIndependent, Variability::kContinuous, "s", "simulated time");
  if (plant) {
    plant_variables(c, b);
  } else {
    controller_variables(c, b);
  }
  Variable& period = b.add("period", Causality::kLocal, Variability::kConstant, "s",
                           "the FMU's period: every communication step is a whole number of them");
  period.initial = Initial::kExact;
  period.start = number_text(static_cast<double>(period_ns) / 1e9);
  return md;
}

}  // namespace quadcosim::fmi
