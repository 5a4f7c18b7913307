// libFuzzer target: any bytes as a scenario, a vehicle file and a controller parameter file.
//
// The bytes are handed to the loaders as a file (an anonymous in-memory file, /proc/self/fd/N), the
// way `quadcosim run|plant|controller|lqr` reads them. A loader may refuse the input with
// io::ConfigError (its message names the file, the key and the value); any other exception, a crash
// or undefined behaviour is a bug. A scenario that loads is also turned into a simulation (which
// designs the LQR gains and checks the schedule: control::CareError and std::invalid_argument are
// its documented refusals) and run for a few ticks.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "control/care.hpp"
#include "hosts/scenario_resolvers.hpp"
#include "io/scenario.hpp"
#include "sim/simulation.hpp"

namespace {

using namespace quadcosim;

// An in-memory file holding the input; closed on destruction.
class MemFile {
 public:
  MemFile(const std::uint8_t* data, std::size_t size) : fd_(memfd_create("fuzz.yaml", 0)) {
    if (fd_ < 0 || write(fd_, data, size) != static_cast<ssize_t>(size)) {
      std::perror("fuzz_config: memfd");
      std::abort();
    }
  }
  ~MemFile() { close(fd_); }
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

void try_scenario(const std::string& path) {
  io::Scenario sc;
  try {
    sc = io::load_scenario(path, hosts::scenario_resolvers());
  } catch (const io::ConfigError&) {
    return;
  }
  sc.simulation.duration_ticks = std::min<sim::Tick>(sc.simulation.duration_ticks, 4);
  try {
    sim::Simulation simulation(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule);
    simulation.run([](const sim::TickRecord&) {});
  } catch (const control::CareError&) {
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const MemFile file(data, size);
  const std::string path = file.path();
  try_scenario(path);
  model::VehicleParams vehicle;
  try {
    vehicle = io::load_vehicle(path);
  } catch (const io::ConfigError&) {
  }
  try {
    io::load_controller(path, vehicle, hosts::scenario_resolvers());
  } catch (const io::ConfigError&) {
  }
  return 0;
}
