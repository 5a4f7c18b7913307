#include "io/sitl_yaml.hpp"

#include <cstdlib>
#include <stdexcept>

#include "sitl/px4.hpp"
#include "sitl/sitl_controller.hpp"

namespace quadcosim::io {

namespace {

std::string resolved(const std::string& given, const std::filesystem::path& folder) {
  const std::filesystem::path p(given);
  // Absolute: the firmware runs in a folder of its own.
  return std::filesystem::absolute(p.is_absolute() ? p : folder / p).lexically_normal().string();
}

}  // namespace

std::shared_ptr<const control::Controller> read_sitl_controller(YamlSection& c, const model::VehicleParams& vehicle,
                                                                const std::filesystem::path& folder) {
  std::optional<YamlSection> section = c.section("sitl");
  YAML::Node empty(YAML::NodeType::Map);
  YamlSection s = section ? *section : YamlSection(empty, c.file(), c.key_path("sitl"));
  sitl::SitlSpec spec;
  spec.firmware = s.choice("firmware", "ardupilot", {"ardupilot", "px4", "betaflight"});
  const bool px4 = spec.firmware == "px4";
  const bool betaflight = spec.firmware == "betaflight";
  std::string binary = s.text("binary", "");
  if (binary.empty()) {
    const char* env = std::getenv(px4 ? kPx4SitlEnv : betaflight ? kBetaflightSitlEnv : kArduPilotSitlEnv);
    if (!env || !*env) {
      if (betaflight) {
        s.fail("binary", std::string("missing; expected the path of Betaflight's SITL executable "
                                     "(obj/main/betaflight_SITL.elf of `make TARGET=SITL`), here or in the "
                                     "environment variable ") +
                             kBetaflightSitlEnv);
      }
      s.fail("binary", px4 ? std::string("missing; expected the path of PX4's SITL executable "
                                         "(build/px4_sitl_default/bin/px4), here or in the environment variable ") +
                                 kPx4SitlEnv
                           : std::string("missing; expected the path of ArduPilot's SITL executable "
                                         "(build/sitl/bin/arducopter), here or in the environment variable ") +
                                 kArduPilotSitlEnv);
    }
    binary = env;
    spec.binary = std::filesystem::absolute(binary).lexically_normal().string();
  } else {
    spec.binary = resolved(binary, folder);
  }
  if (s.has("params")) {
    const YAML::Node n = s.raw("params");
    if (n.IsScalar()) {
      spec.params.push_back(resolved(n.Scalar(), folder));
    } else if (n.IsSequence()) {
      for (const YAML::Node& e : n) {
        if (!e.IsScalar()) s.fail("params", "expected parameter file paths");
        spec.params.push_back(resolved(e.Scalar(), folder));
      }
    } else {
      s.fail("params", "got " + YamlSection::describe(n) + ", expected a parameter file or a list of them");
    }
  }
  if (s.has("work_dir")) spec.work_dir = resolved(s.text("work_dir", ""), folder);
  // Keys of one firmware only.
  for (const char* key : {"home", "pwm_min_us", "pwm_max_us"}) {
    if (px4 && s.has(key)) {
      s.fail(key, std::string("is ArduPilot's; PX4 takes its home from the GNSS (environment.site) and its "
                              "outputs as 0..1 (docs/sitl.md)"));
    }
  }
  for (const char* key : {"home", "pwm_min_us", "pwm_max_us", "mission", "echo_statustext"}) {
    if (betaflight && s.has(key)) {
      s.fail(key, std::string("is not Betaflight's: it flies an RC pilot (arm_at_s, the reference's height) and "
                              "outputs 0..1 (docs/sitl.md, \"Betaflight\")"));
    }
  }
  for (const char* key : {"etc_dir", "airframe", "instance", "settle_ms", "cpu"}) {
    if (!px4 && s.has(key)) s.fail(key, "is PX4's (firmware: px4)");
  }
  for (const char* key : {"arm_at_s", "resend_ms", "realtime_factor"}) {
    if (!betaflight && s.has(key)) s.fail(key, "is Betaflight's (firmware: betaflight)");
  }
  spec.arm_at_s = s.number("arm_at_s", spec.arm_at_s, 0.0, 1e6);
  spec.resend_ms = s.number("resend_ms", spec.resend_ms, 1.0, 60000.0);
  spec.realtime_factor = s.number("realtime_factor", spec.realtime_factor, 0.0, 1000.0);
  if (s.has("etc_dir")) spec.etc_dir = resolved(s.text("etc_dir", ""), folder);
  spec.airframe = static_cast<int>(s.integer("airframe", spec.airframe, 1, 99999999));
  spec.instance = static_cast<int>(s.integer("instance", spec.instance, -1, 99));
  spec.settle_ms = s.number("settle_ms", spec.settle_ms, 0.0, 10000.0);
  spec.cpu = static_cast<int>(s.integer("cpu", spec.cpu, -2, 1023));
  spec.home = s.text("home", spec.home);
  spec.start_timeout_s = s.number("start_timeout_s", spec.start_timeout_s, 0.1, 3600.0);
  spec.timeout_s = s.number("timeout_s", spec.timeout_s, 0.01, 3600.0);
  spec.pwm_min_us = s.number("pwm_min_us", spec.pwm_min_us, 0.0, 3000.0);
  spec.pwm_max_us = s.number("pwm_max_us", spec.pwm_max_us, 0.0, 3000.0);
  for (const YAML::Node& a : s.sequence("args")) {
    if (!a.IsScalar()) s.fail("args", "expected command-line arguments (text)");
    spec.args.push_back(a.Scalar());
  }
  spec.echo_statustext = s.boolean("echo_statustext", false);
  const std::vector<YAML::Node> items = s.sequence("mission");
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string key = "mission[" + std::to_string(i) + "]";
    if (!items[i].IsMap()) s.fail(key, "got " + YamlSection::describe(items[i]) + ", expected a mapping");
    YamlSection m(items[i], s.file(), s.key_path(key));
    sitl::MissionItem item;
    item.at_s = m.number("at_s", 0.0, 0.0, 1e9);
    int kinds = 0;
    if (m.has("mode")) {
      ++kinds;
      item.kind = sitl::MissionItem::Kind::kMode;
      item.mode = m.text("mode", "");
      if (px4 && !sitl::px4::mode_numbers(item.mode)) {
        m.fail("mode", "got '" + item.mode + "', expected one of PX4's " + sitl::px4::mode_names());
      }
      if (!px4 && sitl::copter_mode_number(item.mode) < 0) {
        m.fail("mode", "got '" + item.mode +
                           "', expected stabilize, acro, alt_hold, auto, guided, loiter, rtl, circle, land, poshold "
                           "or brake");
      }
    }
    if (m.has("arm")) {
      ++kinds;
      item.kind = m.boolean("arm", true) ? sitl::MissionItem::Kind::kArm : sitl::MissionItem::Kind::kDisarm;
    }
    if (m.has("takeoff_m")) {
      ++kinds;
      item.kind = sitl::MissionItem::Kind::kTakeoff;
      item.takeoff_m = m.number("takeoff_m", 0.0, 0.1, 1e4);
    }
    if (m.has("goto_m")) {
      ++kinds;
      item.kind = sitl::MissionItem::Kind::kGoto;
      const std::vector<double> p = m.numbers("goto_m", {}, 3);
      item.p_W = {p[0], p[1], p[2]};
    }
    if (kinds != 1) {
      s.fail(key, "expected exactly one of mode, arm, takeoff_m, goto_m (a position [x, y, z] in the world, ENU)");
    }
    m.reject_unknown_keys();
    spec.mission.push_back(item);
  }
  s.reject_unknown_keys();
  try {
    return std::make_shared<sitl::SitlController>(spec, vehicle);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const std::string key = what.rfind("binary", 0) == 0     ? "binary"
                            : what.rfind("params", 0) == 0   ? "params"
                            : what.rfind("firmware", 0) == 0 ? "firmware"
                            : what.rfind("etc_dir", 0) == 0  ? "etc_dir"
                                                             : "";
    if (key.empty()) c.fail("sitl", what);
    s.fail(key, what);
  }
}

}  // namespace quadcosim::io

namespace quadcosim::io {

namespace {

// PX4's default home (its SITL's PX4_HOME_*), and the World Magnetic Model's field there as PX4's own
// tables give it: 48.24 uT, inclination 63.16 deg, declination 3.41 deg.
constexpr double kHomeLat = 47.397742, kHomeLon = 8.545594, kHomeAlt = 488.0;

bool is_px4(const YAML::Node& root) {
  const YAML::Node c = root["controller"];
  if (!c || !c.IsMap()) return false;
  const YAML::Node s = c["sitl"];
  return s && s.IsMap() && s["firmware"] && s["firmware"].IsScalar() && s["firmware"].Scalar() == "px4";
}

double number_or(const YAML::Node& n, double fallback) {
  if (!n || !n.IsScalar()) return fallback;
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    return fallback;
  }
}

}  // namespace

std::vector<std::string> add_px4_sensors(YamlSection& root, double plant_rate_hz, int controller_divider) {
  const YAML::Node view = root.node();
  if (!is_px4(view)) return {};
  YAML::Node tree = root.node();
  std::vector<std::string> added;
  // A rate near `target_hz` that lands on control ticks: the plant rate over a multiple of the divider.
  auto rate = [&](double target_hz) {
    const long c = std::max(1, controller_divider);
    const long n = c * std::max(1L, std::lround(plant_rate_hz / target_hz / static_cast<double>(c)));
    return plant_rate_hz / static_cast<double>(n);
  };
  auto section = [&](const char* parent, const char* name) -> std::optional<YAML::Node> {
    const YAML::Node p = view[parent];
    if (!p || !p.IsMap() || !p[name]) return std::nullopt;
    return p[name];
  };
  auto noise_given = [&](const char* name, const char* key) {
    const auto s = section("sensors", name);
    if (s && s->IsMap() && !(number_or((*s)[key], 0.0) > 0.0)) {
      YamlSection sensors(view["sensors"], root.file(), root.key_path("sensors"));
      YamlSection sec(*s, root.file(), sensors.key_path(name));
      sec.fail(key, std::string(sec.has(key) ? "is 0" : "missing") +
                        ": PX4 takes a sensor whose readings repeat for stale and will not arm; give it noise "
                        "(docs/sitl.md, \"What PX4 needs\")");
    }
  };
  bool at_home = true;
  if (const auto site = section("environment", "site")) {
    at_home = std::abs(number_or((*site)["latitude_deg"], 0.0) - kHomeLat) < 1e-6 &&
              std::abs(number_or((*site)["longitude_deg"], 0.0) - kHomeLon) < 1e-6;
  } else {
    YAML::Node s = tree["environment"]["site"];
    s["latitude_deg"] = kHomeLat;
    s["longitude_deg"] = kHomeLon;
    s["altitude_m"] = kHomeAlt;
    added.emplace_back("environment.site");
  }
  if (const auto imu = section("sensors", "imu")) {
    noise_given("imu", "gyro_noise_density_rad_s_sqrt_hz");
    noise_given("imu", "accel_noise_density_m_s2_sqrt_hz");
  } else {
    YAML::Node s = tree["sensors"]["imu"];
    s["gyro_noise_density_rad_s_sqrt_hz"] = 0.0003;
    s["accel_noise_density_m_s2_sqrt_hz"] = 0.004;
    added.emplace_back("sensors.imu");
  }
  if (section("sensors", "magnetometer")) {
    noise_given("magnetometer", "noise_sigma_uT");
  } else {
    if (!at_home) {
      YamlSection r = root;
      r.fail("sensors",
             "has no magnetometer, and PX4 needs one whose field matches its World Magnetic Model at "
             "environment.site: give sensors.magnetometer (field_uT, inclination_deg, declination_deg "
             "of the site, noise_sigma_uT); quadcosim adds one only at PX4's default home, "
             "47.397742 N 8.545594 E (docs/sitl.md)");
    }
    YAML::Node s = tree["sensors"]["magnetometer"];
    s["rate_hz"] = rate(50.0);
    s["field_uT"] = 48.24;
    s["inclination_deg"] = 63.16;
    s["declination_deg"] = 3.41;
    s["noise_sigma_uT"] = 0.3;
    added.emplace_back("sensors.magnetometer");
  }
  if (section("sensors", "barometer")) {
    noise_given("barometer", "noise_sigma_Pa");
  } else {
    YAML::Node s = tree["sensors"]["barometer"];
    s["rate_hz"] = rate(50.0);
    s["noise_sigma_Pa"] = 1.2;
    added.emplace_back("sensors.barometer");
  }
  if (!section("sensors", "gnss")) {
    YAML::Node s = tree["sensors"]["gnss"];
    s["rate_hz"] = rate(10.0);
    s["horizontal_sigma_m"] = 0.3;
    s["vertical_sigma_m"] = 0.5;
    s["velocity_sigma_m_s"] = 0.05;
    added.emplace_back("sensors.gnss");
  }
  return added;
}

std::shared_ptr<const control::Controller> with_px4_site(std::shared_ptr<const control::Controller> controller,
                                                         const sensors::SensorSet& sensors,
                                                         std::vector<std::string> added) {
  const auto* s = dynamic_cast<const sitl::SitlController*>(controller.get());
  if (!s || !s->px4()) return controller;
  return s->with_site(sensors.gnss ? sensors.gnss->site : sensors::Geodetic{}, std::move(added));
}

}  // namespace quadcosim::io
