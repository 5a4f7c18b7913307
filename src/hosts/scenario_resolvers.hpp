// The resolvers a process that hosts runs hands to io::load_scenario (io/scenario_resolvers.hpp): the
// FMUs a scenario names, loaded through a cache the host owns, and (when the host has an interpreter)
// the Python classes.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "fmi/fmu.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

/// Loads the FMUs of scenarios: each file's description and binary once, shared by every scenario that
/// names it while any of them lives (a sweep loads its scenario once per run); a file rewritten since
/// is loaded again. Its cache lives as long as the loader (one per process that hosts runs).
class FmuLoader final : public io::FmuResolver {
 public:
  std::shared_ptr<const sim::ExternalDynamicsFactory> plant(const io::FmuSpec& spec) const override;
  std::shared_ptr<const control::Controller> controller(const io::FmuSpec& spec,
                                                        const model::VehicleParams& vehicle) const override;
  std::string sensors_error(const control::Controller& controller, const sensors::SensorSet& carried) const override;

 private:
  std::shared_ptr<fmi::Fmu> load(const std::string& path) const;

  mutable std::mutex mutex_;
  mutable std::map<std::string, std::pair<std::filesystem::file_time_type, std::weak_ptr<fmi::Fmu>>> cache_;
};

/// Resolvers that load FMUs through a new FmuLoader (owned by the resolvers and their copies) and make
/// Python classes through `python` (empty: refused), finding their modules' files with `python_module`.
io::ScenarioResolvers scenario_resolvers(io::PythonControllerFactory python = {},
                                         io::PythonModuleLocator python_module = {});

}  // namespace quadcosim::hosts
