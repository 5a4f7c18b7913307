#include "io/sitl_yaml.hpp"

#include <cstdlib>
#include <stdexcept>

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
  spec.firmware = s.choice("firmware", "ardupilot", {"ardupilot"});
  std::string binary = s.text("binary", "");
  if (binary.empty()) {
    const char* env = std::getenv(kArduPilotSitlEnv);
    if (!env || !*env) {
      s.fail("binary", std::string("missing; expected the path of ArduPilot's SITL executable "
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
      if (sitl::copter_mode_number(item.mode) < 0) {
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
                                                             : "";
    if (key.empty()) c.fail("sitl", what);
    s.fail(key, what);
  }
}

}  // namespace quadcosim::io
