// In-process co-simulation of one vehicle: plant and controller nodes on the deterministic in-process
// transport, driven by the integer-tick multi-rate scheduler.
//
// Per plant tick k (time t_k = k * period):
//   0. messages held back by injected delays (SimulationConfig::faults) and due by tick k arrive;
//   1. scheduled parameter changes due at t_k are applied to the controller;
//   2. the plant publishes /clock, Pose, Velocity, Imu for x(t_k);
//   3. on every `controller_divider`-th tick the controller steps and publishes a command;
//   4. the plant latches the command in effect (zero-order hold, after the configured delay);
//   5. the tick is recorded (state at t_k, command over [t_k, t_k+1), the controller's latest status
//      as received on its status topic);
//   6. the plant integrates to t_k+1 (not after the last tick).
// Same inputs, same bytes: nothing here reads a wall clock or an unseeded random source (the plant's
// noise comes from the scenario's seed, sim/realism.hpp).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "sim/clock.hpp"
#include "sim/controller_node.hpp"
#include "sim/faults.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::sim {

struct SimulationConfig {
  PlantOptions plant;
  int controller_divider = 2;  ///< controller period = divider * plant period
  Tick duration_ticks = 1500;  ///< last recorded tick
  std::string ns = "/drone";
  FaultConfig faults;  ///< injected message loss and delay (in-process only; none by default)
};

/// One recorded tick.
struct TickRecord {
  Tick tick;
  double t_s;
  const model::State& state;
  const model::Vector4& latched_command;  ///< rotor command acting over [t_k, t_k+1) [rad/s]
  const msg::ControllerStatus& status;    ///< the controller's latest step, as published
};

class Simulation {
 public:
  /// Throws std::invalid_argument when a scheduled parameter is refused by the controller.
  Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle,
             const model::State& initial, const control::ControllerConfig& controller,
             std::vector<ScheduledParameter> schedule);

  /// Runs ticks 0..duration_ticks, calling on_tick for each.
  void run(const std::function<void(const TickRecord&)>& on_tick);

  /// Steps 1-6 above for tick k without recording: what run() does per tick. Call with k = 0, 1, ...
  /// in order (a swarm advances many simulations tick by tick, or block by block).
  void tick(Tick k) {
    begin_tick(k);
    end_tick(k);
  }
  /// Steps 1-4 of tick k (schedule, outputs, controller, latch).
  void begin_tick(Tick k);
  /// Step 6 of tick k (integrate to t_k+1; nothing after the last tick).
  void end_tick(Tick k) {
    if (k < config_.duration_ticks) plant_.integrate(k);
  }
  /// The current state, the command acting over [t_k, t_k+1) and the latest status, after
  /// begin_tick(k) (for recorders that do not go through run()).
  TickRecord record(Tick k) const;

  const PlantNode& plant() const { return plant_; }
  /// The bus the nodes talk on, for observers such as recorders (subscribe before run()).
  Transport& transport() { return transport_; }
  /// Messages lost to injected faults on `topic` so far.
  std::uint64_t dropped(const std::string& topic) const { return transport_.dropped(topic); }
  const ControllerNode& controller() const { return controller_; }

 private:
  SimulationConfig config_;
  InProcessTransport transport_;
  PlantNode plant_;
  ControllerNode controller_;
  ParameterSchedule schedule_;
  double control_dt_s_;
  msg::ControllerStatus status_;  ///< the last status delivered, when faults may lose or delay statuses
  const msg::ControllerStatus* delivered_status_ = nullptr;  ///< status_, or the controller's own
};

}  // namespace quadcosim::sim
