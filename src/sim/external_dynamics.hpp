// Plant dynamics computed outside quadcosim's 6-DOF model (a co-simulation FMU, fmi/fmu_plant.hpp):
// the plant node keeps everything else (integer ticks, command checks, delay, watchdog, sensor
// realism, topics, status) and asks this for the outputs at t_k and for the step to t_k+1.
// PlantOptions::external selects it; null keeps the native model (sim/plant_node.hpp).
#pragma once

#include <memory>
#include <string>

#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"
#include "sim/clock.hpp"

namespace quadcosim::sim {

class ExternalDynamics {
 public:
  virtual ~ExternalDynamics() = default;
  /// The true outputs `y` (what noise-free sensors read) and the state `x` to record, at t_k. Called
  /// once or more per tick, before step(k). x.omega_rad_s: the rotor speeds if the dynamics report
  /// them, else the command acting.
  virtual void outputs(Tick k, model::Outputs& y, model::State& x) = 0;
  /// Advances from t_k to t_k+1 (one plant period) under the rotor speed command `omega_rad_s`
  /// [rad/s], already checked and clamped to [0, omega_max] by the node. Throws
  /// std::runtime_error naming the tick when the dynamics fail (the run ends with that message).
  virtual void step(Tick k, const model::RotorVector& omega_rad_s) = 0;
};

/// Makes one ExternalDynamics per plant (a swarm makes one per vehicle), starting at `initial`.
class ExternalDynamicsFactory {
 public:
  virtual ~ExternalDynamicsFactory() = default;
  /// Throws std::runtime_error (a message naming what does not fit) when it cannot.
  virtual std::unique_ptr<ExternalDynamics> make(const model::VehicleParams& vehicle, const model::State& initial,
                                                 const TickClock& clock) const = 0;
  /// For logs and reports: "FMU quadrotor.fmu (model 'Quadrotor', FMI 2.0)".
  virtual std::string describe() const = 0;
  /// "" when make() can fly `vehicle`, else why not (the FMU has another rotor count): what a
  /// scenario is checked by when it is loaded, so that the refusal is bad input, not a failed run.
  virtual std::string check(const model::VehicleParams& /*vehicle*/) const { return {}; }
};

}  // namespace quadcosim::sim
