// `quadcosim fmu export` and `fmu info` (docs/fmi.md): quadcosim's plant or controller packed as an FMI
// co-simulation FMU (fmi/export/fmu_config.hpp says what it holds): modelDescription.xml (describe()
// through write_model_description), the FMU library (quadcosim_fmu) as
// binaries/<platform>/<modelIdentifier>.so and the configuration as resources/quadcosim.json, zipped;
// and what an FMU (any tool's) declares. The front end finds the library and prints what was done.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fmi/export/fmu_config.hpp"
#include "fmi/model_description.hpp"
#include "io/scenario_resolvers.hpp"

namespace quadcosim::hosts {

/// What `fmu export` packs.
struct FmuExportOptions {
  std::string kind;             ///< "plant" or "controller"
  std::string scenario;         ///< "" for the defaults (the paper's vehicle and controller)
  std::string controller;       ///< replaces the scenario's controller.type ("" keeps it)
  int fmi = 2;                  ///< FMI version, 2 or 3
  std::string out;              ///< the .fmu to write
  std::string generation_tool;  ///< modelDescription's generationTool ("quadcosim VERSION")
};

/// The platform folder of binaries/ for this machine in FMI `version`, or "" when the standard
/// names none (FMI 2 defines Linux folders for x86 only).
std::string platform_folder(fmi::FmiVersion version);

/// The FMU's configuration from the scenario (or the defaults: the paper's vehicle and controller);
/// what the scenario says that the FMU does not carry is added to `notes`. Throws io::ConfigError and
/// std::invalid_argument for what cannot be packed.
fmi::FmuConfig fmu_config_from(const FmuExportOptions& o, std::vector<std::string>& notes);

/// What `export_fmu` wrote.
struct FmuExport {
  fmi::FmuConfig config;
  fmi::ModelDescription description;
  std::string platform;            ///< the binaries/ folder
  std::filesystem::path library;   ///< the FMU library packed
  std::vector<std::string> notes;  ///< what the scenario says that the FMU does not carry
};

/// Writes the FMU `o.out` with the library `find_library` returns (asked once the configuration is
/// known to be packable; it throws to say the library is missing). Throws std::invalid_argument for
/// bad input (the file name, the scenario, a setting an FMU cannot express) and fmi::FmuError when
/// the archive cannot be written.
FmuExport export_fmu(const FmuExportOptions& o, const std::function<std::filesystem::path()>& find_library,
                     const io::ScenarioResolvers& resolvers);

/// What an FMU declares, and whether it has a binary for this machine.
struct FmuInfo {
  fmi::ModelDescription description;
  std::vector<std::string> platforms;  ///< its binaries/ folders, sorted
  std::string here;                    ///< this machine's folder (platform_folder), "" when none
  bool runs_here = false;              ///< binaries/<here>/<modelIdentifier>.so is in it
};

/// Unpacks and reads the FMU at `path`. Throws std::invalid_argument for what is not an FMU.
FmuInfo read_fmu_info(const std::string& path);

}  // namespace quadcosim::hosts
