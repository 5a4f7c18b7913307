// The plant seam for dynamics computed elsewhere (sim/external_dynamics.hpp): a plant node whose
// ExternalDynamics wraps quadcosim's own model writes the same trajectory.csv, byte for byte, as the
// native plant node; what only the native model can do (wind, rotor faults, drag) is refused by key.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "hosts/scenario_resolvers_test_support.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/external_dynamics.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = QUADCOSIM_SOURCE_DIR;

/// How often the dynamics were called, over every instance a factory made.
struct Calls {
  int made = 0, outputs = 0, steps = 0;
};

/// The native model behind the external seam: what an FMU of quadcosim's own plant computes.
class NativeDynamics final : public sim::ExternalDynamics {
 public:
  NativeDynamics(const model::VehicleParams& vehicle, const model::State& initial, const sim::TickClock& clock,
                 int substeps, Calls& calls)
      : calls_(calls),
        model_(vehicle),
        x_(initial),
        cmd_(model_.rotor_input(initial.omega_rad_s)),
        clock_(clock),
        substeps_(substeps) {}

  void outputs(sim::Tick k, model::Outputs& y, model::State& x) override {
    y = model_.outputs(clock_.seconds(k), x_, cmd_);
    x = x_;
    ++calls_.outputs;
  }
  void step(sim::Tick k, const model::RotorVector& omega_rad_s) override {
    cmd_ = model_.rotor_input(omega_rad_s);
    model_.step(x_, clock_.seconds(k), cmd_, clock_.period_s(), substeps_);
    ++calls_.steps;
  }

 private:
  Calls& calls_;
  model::Quadrotor model_;
  model::State x_;
  model::RotorInput cmd_;
  sim::TickClock clock_;
  int substeps_;
};

class NativeFactory final : public sim::ExternalDynamicsFactory {
 public:
  explicit NativeFactory(int substeps) : substeps_(substeps) {}
  std::unique_ptr<sim::ExternalDynamics> make(const model::VehicleParams& vehicle, const model::State& initial,
                                              const sim::TickClock& clock) const override {
    ++calls.made;
    return std::make_unique<NativeDynamics>(vehicle, initial, clock, substeps_, calls);
  }
  std::string describe() const override { return "the native model behind the external seam"; }
  mutable Calls calls;

 private:
  int substeps_;
};

/// trajectory.csv of `sc` flown in-process, as `quadcosim run` writes it.
std::string trajectory_csv(const Scenario& sc, const fs::path& path) {
  sim::Simulation simulation(sc.simulation, sc.vehicle, initial_state(sc), sc.controller, sc.schedule);
  {
    TrajectoryWriter csv(path.string());
    simulation.run([&](const sim::TickRecord& r) {
      csv.write(r.t_s, r.state, r.latched_command, ControlColumns::from(r.status),
                simulation.plant().watchdog_active());
    });
    csv.close();
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class ExternalPlant : public ::testing::TestWithParam<const char*> {};

TEST_P(ExternalPlant, NativeModelBehindTheSeamWritesTheSameTrajectoryCsv) {
  const fs::path dir = fs::temp_directory_path() / ("quadcosim_external_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Scenario sc = load_scenario((kSourceDir / "scenarios" / GetParam()).string(), hosts::test_resolvers());
  const std::string native = trajectory_csv(sc, dir / "native.csv");

  auto factory = std::make_shared<NativeFactory>(sc.simulation.plant.substeps);
  sc.simulation.plant.external = factory;
  const std::string external = trajectory_csv(sc, dir / "external.csv");
  fs::remove_all(dir);

  EXPECT_EQ(factory->calls.made, 1);
  EXPECT_EQ(factory->calls.steps, sc.simulation.duration_ticks);  // not after the last tick
  ASSERT_GT(native.size(), 10000u);
  EXPECT_TRUE(native == external) << "trajectory.csv differs behind the external seam";
}

// The paper's four experiments and one with sensor noise (realism applies on top of either plant).
INSTANTIATE_TEST_SUITE_P(Scenarios, ExternalPlant,
                         ::testing::Values("paper/altitude_step.yaml", "paper/roll_step.yaml", "paper/pitch_step.yaml",
                                           "paper/yaw_step.yaml", "realism/roll_step_noisy_imu.yaml"));

TEST(ExternalPlantSeam, OutputsForEveryPublicationAndOneStepPerTick) {
  Scenario sc = load_scenario((kSourceDir / "scenarios/paper/altitude_step.yaml").string(), hosts::test_resolvers());
  auto factory = std::make_shared<NativeFactory>(1);
  sc.simulation.plant.external = factory;
  sim::InProcessTransport bus;
  sim::PlantNode plant(bus, sim::Topics::for_namespace("/drone"), sc.vehicle, sc.simulation.plant, initial_state(sc));
  for (sim::Tick k = 0; k < 5; ++k) {
    plant.publish_outputs(k);
    plant.publish_outputs(k);  // a lockstep repeat asks again
    plant.latch_command(k);
    plant.integrate(k);
  }
  EXPECT_EQ(factory->calls.made, 1);
  EXPECT_EQ(factory->calls.outputs, 10);
  EXPECT_EQ(factory->calls.steps, 5);
}

TEST(ExternalPlantSeam, NativeOnlyFeaturesAreRefusedByKey) {
  const Scenario base =
      load_scenario((kSourceDir / "scenarios/paper/altitude_step.yaml").string(), hosts::test_resolvers());
  auto expect_refused = [&](Scenario sc, const std::string& key) {
    sc.simulation.plant.external = std::make_shared<NativeFactory>(1);
    EXPECT_EQ(sim::external_plant_conflict(sc.simulation.plant.realism, sc.vehicle), key);
    sim::InProcessTransport bus;
    try {
      sim::PlantNode plant(bus, sim::Topics::for_namespace("/drone"), sc.vehicle, sc.simulation.plant,
                           initial_state(sc));
      ADD_FAILURE() << "not refused: " << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(key + ": ", 0), 0u) << e.what();
    }
  };
  Scenario wind = base;
  wind.simulation.plant.realism.wind.mean_W_m_s = {2.0, 0.0, 0.0};
  expect_refused(wind, "environment");
  Scenario faults = base;
  faults.simulation.plant.realism.faults.push_back({100, 0, 0.5});
  expect_refused(faults, "faults");
  Scenario drag = base;
  drag.vehicle.aero.quadratic_drag_N_s2_m2.y() = 0.1;
  expect_refused(drag, "vehicle.aero.quadratic_drag_N_s2_m2.y");
  EXPECT_EQ(sim::external_plant_conflict(base.simulation.plant.realism, base.vehicle), "");
}

}  // namespace
}  // namespace quadcosim::io
