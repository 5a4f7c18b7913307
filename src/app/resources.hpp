// Where the CLI finds what ships beside it: the Python tools (plots, report), the scenarios and the
// FMU library. In a build tree they are the source tree's (tools/, scenarios/) and build/lib/; after
// `cmake --install build --prefix P` they are P/share/quadcosim/{tools,scenarios} and
// P/lib/quadcosim/. The installed layout is looked for first, next to the executable, so an installed
// quadcosim never reads the source tree it was built from (which may be gone).
#pragma once

#include <filesystem>
#include <string>

namespace quadcosim::app {

/// The folder of the running executable, or "" when /proc/self/exe cannot be read.
std::filesystem::path executable_dir();

/// The shipped folder `name` ("tools" or "scenarios"): $<env> when set and not empty, else
/// <exe>/../share/quadcosim/<name> when it exists, else `build_tree` (the source tree's folder).
std::filesystem::path resource_dir(const std::string& name, const char* env, const char* build_tree);

/// The tools folder (tools/*.py): $QUADCOSIM_TOOLS_DIR, installed, or the source tree's.
std::filesystem::path tools_dir();

/// The scenarios folder: $QUADCOSIM_SCENARIOS_DIR, installed, or the source tree's.
std::filesystem::path scenarios_dir();

}  // namespace quadcosim::app
