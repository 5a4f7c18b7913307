// The version and the git commit the build was configured at (src/io/CMakeLists.txt), which the
// provenance record of every run carries.
#pragma once

namespace quadcosim::io {

/// The project's version ("0.1.0"; "unknown" when the build did not say).
const char* build_version();

/// The commit HEAD was at when the build was configured ("unknown" outside a git checkout).
const char* build_git_commit();

}  // namespace quadcosim::io
