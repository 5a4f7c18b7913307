#include "drivers/lockstep_plant_driver.hpp"

#include <utility>

namespace quadcosim::drivers {

std::string to_string(TimeoutPolicy p) { return p == TimeoutPolicy::kHold ? "hold" : "abort"; }

std::vector<sim::SteppablePlant*> LockstepPlantDriver::plant_pointers(const std::vector<DrivenPlant>& plants) {
  std::vector<sim::SteppablePlant*> v;
  v.reserve(plants.size());
  for (const DrivenPlant& p : plants) v.push_back(p.plant);
  return v;
}

LockstepPlantDriver::LockstepPlantDriver(std::vector<DrivenPlant> plants, const LockstepOptions& options,
                                         LockstepHooks hooks, DriverHost& host)
    // plants copied, not moved: the order in which the arguments are formed is unspecified.
    : core_(plant_pointers(plants), options, Hooks{std::move(hooks), plants}, host) {}

}  // namespace quadcosim::drivers
