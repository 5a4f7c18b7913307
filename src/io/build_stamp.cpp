// A unit of its own, compiled with the version and the commit as macros (src/io/CMakeLists.txt): a new
// commit recompiles these few lines, not the provenance code, which stays in quadcosim_io's batches.
#include "io/build_stamp.hpp"

#ifndef QUADCOSIM_VERSION
#define QUADCOSIM_VERSION "unknown"
#endif
#ifndef QUADCOSIM_GIT_COMMIT
#define QUADCOSIM_GIT_COMMIT "unknown"
#endif

namespace quadcosim::io {

const char* build_version() { return QUADCOSIM_VERSION; }

const char* build_git_commit() { return QUADCOSIM_GIT_COMMIT; }

}  // namespace quadcosim::io
