// hosts/scenario_resolvers.hpp: the FMU loader and the resolvers of a process that hosts runs.
#include "hosts/scenario_resolvers.hpp"

#include "fmi/fmu_controller.hpp"
#include "fmi/fmu_plant.hpp"

namespace quadcosim::hosts {

std::shared_ptr<fmi::Fmu> FmuLoader::load(const std::string& path) const {
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(path, ec);
  const std::lock_guard lock(mutex_);
  auto& entry = cache_[path];
  if (auto fmu = entry.second.lock(); fmu && !ec && entry.first == mtime) return fmu;
  std::shared_ptr<fmi::Fmu> fmu = fmi::Fmu::load(path);
  entry = {mtime, fmu};
  return fmu;
}

std::shared_ptr<const sim::ExternalDynamicsFactory> FmuLoader::plant(const io::FmuSpec& spec) const {
  return std::make_shared<const fmi::FmuPlant>(load(spec.path), spec.mapping);
}

std::shared_ptr<const control::Controller> FmuLoader::controller(const io::FmuSpec& spec,
                                                                 const model::VehicleParams& vehicle) const {
  return std::make_shared<fmi::FmuController>(load(spec.path), spec.mapping, vehicle);
}

std::string FmuLoader::sensors_error(const control::Controller& controller, const sensors::SensorSet& carried) const {
  const fmi::FmuController* fmu = fmi::fmu_controller(controller);
  return fmu ? fmu->check_sensors(carried) : std::string();
}

io::ScenarioResolvers scenario_resolvers(io::PythonControllerFactory python, io::PythonModuleLocator python_module) {
  return {.python = std::move(python),
          .python_module = std::move(python_module),
          .fmu = std::make_shared<const FmuLoader>()};
}

}  // namespace quadcosim::hosts
