#include "sim/topics.hpp"

#include <cctype>

namespace quadcosim::sim {

Topics Topics::for_namespace(const std::string& ns) {
  std::string base = ns;
  while (base.size() > 1 && base.back() == '/') base.pop_back();
  if (base == "/") base.clear();
  Topics t{base + "/motor_commands",
           base + "/Pose",
           base + "/Velocity",
           base + "/Imu",
           "/clock",
           base + "/controller_status",
           base + "/plant_status",
           "/tf",
           "/tf_static",
           base + "/robot_description",
           base + "/scene",
           base,
           {}};
  for (int i = 0; i < control::kCommandLevelCount; ++i) {
    t.level_commands[static_cast<std::size_t>(i)] =
        base + "/cmd/" + std::string(control::to_string(static_cast<control::CommandLevel>(i)));
  }
  return t;
}

std::string validate_namespace(const std::string& ns) {
  if (ns.empty() || ns.front() != '/') return "a namespace must start with '/', got '" + ns + "'";
  bool token_start = true;
  for (std::size_t i = 1; i < ns.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(ns[i]);
    if (c == '/') {
      if (token_start) return "a namespace may not contain '//', got '" + ns + "'";
      token_start = true;
      continue;
    }
    if (!(std::isalnum(c) || c == '_')) {
      return "a namespace may contain only letters, digits, '_' and '/', got '" + ns + "'";
    }
    if (token_start && std::isdigit(c)) {
      return "a namespace part may not start with a digit, got '" + ns + "'";
    }
    token_start = false;
  }
  return {};
}

}  // namespace quadcosim::sim
