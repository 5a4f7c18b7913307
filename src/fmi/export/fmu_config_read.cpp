// The FMU's configuration read back from the JSON to_json (fmu_config_write.cpp) wrote: every key
// checked, an error naming the key path that is missing, unknown or malformed.
#include <limits>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "fmi/export/fmu_config.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::fmi {

using nlohmann::json;

namespace {

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

/// A spin sign: 1 or -1.
int read_spin(const Reader& e) {
  const double s = e.number();
  if (s != 1.0 && s != -1.0) e.fail("", "is not 1 or -1");
  return static_cast<int>(s);
}

/// vehicle.rotors: a custom layout's 4 to 8 rotors, each {position_m: [x, y, z], spin: 1 or -1}.
void read_rotors(const Reader& e, model::VehicleParams& v) {
  if (!e.raw().is_array() || e.raw().size() < static_cast<std::size_t>(model::kMinRotors) ||
      e.raw().size() > static_cast<std::size_t>(model::kMaxRotors)) {
    e.fail("", "is not a list of 4 to 8 rotors {position_m: [x, y, z], spin: 1 or -1}");
  }
  v.rotor_count = static_cast<int>(e.raw().size());
  for (std::size_t i = 0; i < e.raw().size(); ++i) {
    const Reader rotor = Reader(e.raw()[i], e.path() + "[" + std::to_string(i) + "]").with_source(e.source());
    if (!rotor.raw().is_object()) rotor.fail("", "is not {position_m: [x, y, z], spin: 1 or -1}");
    v.rotor_positions_m[i] = rotor.at("position_m").vector<3>();
    v.spin[i] = read_spin(rotor.at("spin"));
  }
}

model::VehicleParams read_vehicle(const Reader& r) {
  model::VehicleParams v;
  // In the table's order: the layout (which sets a standard layout's rotor count), the rotors (a custom
  // layout's count, positions and spins), then one spin sign per rotor.
  for (const auto& p : model::vehicle_parameters()) {
    if (p.kind == model::VehicleParameter::Kind::kRotors) {
      const std::string key(p.name);
      if (v.layout == model::RotorLayout::kCustom) {
        read_rotors(r.at(key), v);
      } else if (r.has(key)) {
        r.at(key).fail("", std::string("is given, but layout ") + model::to_string(v.layout) +
                               " places its rotors itself (rotors go with layout custom)");
      }
      continue;
    }
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
        const auto n = static_cast<std::size_t>(v.rotor_count);
        if (!e.raw().is_array() || e.raw().size() != n) {
          e.fail("", "is not a list of " + std::to_string(n) + " signs (one per rotor of layout " +
                         model::to_string(v.layout) + ")");
        }
        for (std::size_t i = 0; i < n; ++i) {
          const Reader sign = Reader(e.raw()[i], e.path() + "[" + std::to_string(i) + "]").with_source(e.source());
          const int s = read_spin(sign);
          if (v.layout == model::RotorLayout::kCustom && s != v.spin[i]) {
            sign.fail("", "is " + std::to_string(s) + ", but rotors[" + std::to_string(i) + "].spin is " +
                              std::to_string(v.spin[i]));
          }
          v.spin[i] = s;
        }
        break;
      }
      case model::VehicleParameter::Kind::kRotors: break;  // read above
    }
  }
  // The rotor rules of a vehicle file (count, signs, distinct positions, a mixer of full rank).
  if (std::string err = model::validate_rotors(v); !err.empty()) {
    r.at(v.layout == model::RotorLayout::kCustom ? "rotors" : "spin").fail("", "is refused: " + err);
  }
  return v;
}

/// `n` numbers, one per rotor.
model::RotorVector read_rotor_vector(const Reader& e, int n) {
  if (!e.raw().is_array() || e.raw().size() != static_cast<std::size_t>(n)) {
    e.fail("", "not an array of " + std::to_string(n) + " numbers (one per rotor)");
  }
  model::RotorVector x(n);
  for (int i = 0; i < n; ++i) x[i] = Reader(e.raw()[static_cast<std::size_t>(i)], e.path()).number();
  return x;
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
  // The periodic curves: their start (centre, altitude, start and ramp times), then what is their
  // own (`own` reads it into the parameters), then their yaw (the centre only for the circle).
  const auto curve = [&r](auto params, bool centre_yaw, const auto& own) -> trajectory::TrajectorySpec {
    params.centre_m = r.at("centre_m").vector<2>();
    params.altitude_m = r.at("altitude_m").number();
    params.start_s = r.at("start_s").number();
    params.ramp_s = r.at("ramp_s").number();
    own(params);
    params.yaw_mode = read_yaw_mode(r.at("yaw_mode"), centre_yaw);
    params.yaw_rad = r.at("yaw_rad").number();
    return params;
  };
  if (kind == "circle") {
    return curve(trajectory::CircleParams(), true, [&r](trajectory::CircleParams& c) {
      c.radius_m = r.at("radius_m").number();
      c.period_s = r.at("period_s").number();
      const std::string direction = r.at("direction").text();
      if (direction != "ccw" && direction != "cw") r.at("direction").fail("", "is '" + direction + "', not ccw or cw");
      c.clockwise = direction == "cw";
      c.phase_rad = r.at("phase_rad").number();
    });
  }
  if (kind == "lissajous") {
    return curve(trajectory::LissajousParams(), false, [&r](trajectory::LissajousParams& l) {
      l.amplitude_m = r.at("amplitude_m").vector<2>();
      l.period_s = r.at("period_s").vector<2>();
      l.phase_rad = r.at("phase_rad").vector<2>();
    });
  }
  if (kind == "figure8") {
    return curve(trajectory::Figure8Params(), false, [&r](trajectory::Figure8Params& f) {
      f.amplitude_m = r.at("amplitude_m").vector<2>();
      f.period_s = r.at("period_s").number();
    });
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
  c.initial.omega_rad_s = read_rotor_vector(init.at("omega"), c.vehicle.rotor_count);

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
    if (rf.rotor < 0 || rf.rotor >= c.vehicle.rotor_count) {
      f.at("rotor").fail("", "must be 0.." + std::to_string(c.vehicle.rotor_count - 1) + " (one of the vehicle's " +
                                 std::to_string(c.vehicle.rotor_count) + " rotors)");
    }
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

}  // namespace quadcosim::fmi
