// In-process co-simulation of one vehicle: plant and controller nodes on the deterministic in-process
// transport, advanced by the same drivers as over DDS (drivers/): a LockstepPlantDriver over the one
// plant, the controller stepped by a LockstepControllerDriver (sim::LockstepStepper), over an
// InProcessHost that delivers synchronously.
//
// Per plant tick k (time t_k = k * period), the lockstep driver's order:
//   0. messages held back by injected delays (SimulationConfig::faults) and due by tick k arrive
//      (the driver's before_outputs);
//   1. the plant publishes /clock, Pose, Velocity, Imu for x(t_k); when the last sample of a control
//      tick (k % controller_divider == 0) is delivered, the controller applies the parameter changes
//      scheduled by t_k and steps, publishing its command (the answer is in when publish returns);
//   2. the plant latches the command in effect (zero-order hold, after the configured delay);
//   3. the tick is recorded (state at t_k, command over [t_k, t_k+1), the controller's latest status
//      as received on its status topic);
//   4. the plant integrates to t_k+1 (not after the last tick).
// Injected faults: an answer that is not in when publish_outputs returns (a lost or delayed command)
// is a timeout of zero: the driver holds the plant's last command without waiting or asking again,
// as a plant on a lossy link does, and resumes when commands come again. When sensor messages may be
// lost or delayed a complete sample of a control tick may never come: the controller then steps on
// the tick instead (the driver's after_outputs), after the changes scheduled by t_k (before_outputs),
// on the data it has, as a controller on a lossy link steps on its own period.
// Same inputs, same bytes: nothing here reads a wall clock or an unseeded random source (the plant's
// noise comes from the scenario's seed, sim/realism.hpp).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "drivers/controller_drivers.hpp"
#include "drivers/lockstep_plant_driver.hpp"
#include "inproc/inprocess_host.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/plant_node.hpp"
#include "sim/simulation_config.hpp"

namespace quadcosim::inproc {

using sim::SimulationConfig;
using sim::TickRecord;

class Simulation {
 public:
  Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle,
             const model::State& initial, const control::ControllerConfig& controller,
             std::vector<sim::ScheduledParameter> schedule);
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Runs ticks 0..duration_ticks, calling on_tick for each (after the latch, before integrating).
  /// Throws std::invalid_argument when a scheduled parameter is refused by the controller.
  void run(const std::function<void(const TickRecord&)>& on_tick);

  /// Runs the ticks after the last one run up to `last` (<= duration_ticks), calling on_tick (when
  /// given) for each: a swarm advances many simulations block by block. run() is run_ticks(duration).
  void run_ticks(sim::Tick last, const std::function<void(const TickRecord&)>& on_tick = {});
  /// Runs tick k (the one after the last one run) without recording.
  void tick(sim::Tick k) { run_ticks(k); }

  const sim::PlantNode& plant() const { return plant_; }
  /// The bus the nodes talk on, for observers such as recorders (subscribe before run()).
  sim::Transport& transport() { return transport_; }
  /// Messages lost to injected faults on `topic` so far.
  std::uint64_t dropped(const std::string& topic) const { return transport_.dropped(topic); }
  const sim::ControllerNode& controller() const { return controller_; }

 private:
  /// The current state, the command acting over [t_k, t_k+1) and the latest status, after tick k's latch.
  TickRecord record(sim::Tick k) const;

  SimulationConfig config_;
  sim::InProcessTransport transport_;
  sim::PlantNode plant_;
  sim::ControllerNode controller_;
  msg::ControllerStatus status_;  ///< the last status delivered, when faults may lose or delay statuses
  const msg::ControllerStatus* delivered_status_ = nullptr;  ///< status_, or the controller's own
  /// Under injected sensor faults: the controller steps on the tick, after this schedule.
  std::optional<sim::ParameterSchedule> tick_schedule_;
  const std::function<void(const TickRecord&)>* on_tick_ = nullptr;  ///< during run_ticks
  InProcessHost host_;
  std::optional<drivers::LockstepControllerDriver> controller_driver_;  ///< steps on complete samples
  std::optional<drivers::LockstepPlantDriver> driver_;
};

}  // namespace quadcosim::inproc
