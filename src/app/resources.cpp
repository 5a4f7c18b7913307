#include "app/resources.hpp"

#include <cstdlib>
#include <system_error>

namespace quadcosim::app {

namespace fs = std::filesystem;

fs::path executable_dir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path{} : self.parent_path();
}

fs::path resource_dir(const std::string& name, const char* env, const char* build_tree) {
  if (const char* v = std::getenv(env); v != nullptr && *v != '\0') return v;
  if (const fs::path exe = executable_dir(); !exe.empty()) {
    const fs::path installed = exe.parent_path() / "share" / "quadcosim" / name;
    std::error_code ec;
    if (fs::is_directory(installed, ec)) return installed;
  }
  return build_tree;
}

fs::path tools_dir() { return resource_dir("tools", "QUADCOSIM_TOOLS_DIR", QUADCOSIM_TOOLS_DIR); }

fs::path scenarios_dir() { return resource_dir("scenarios", "QUADCOSIM_SCENARIOS_DIR", QUADCOSIM_SCENARIOS_DIR); }

}  // namespace quadcosim::app
