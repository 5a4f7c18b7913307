// In-process co-simulation of one vehicle: plant and controller nodes on the deterministic in-process
// transport, driven by the lockstep loop every driver runs (sim/lockstep_core.hpp) over a synchronous
// host: the answers to tick k are in when its outputs and the controller's step return, so nothing
// waits and nothing reads a wall clock.
//
// Per plant tick k (time t_k = k * period):
//   0. messages held back by injected delays (SimulationConfig::faults) and due by tick k arrive;
//   1. scheduled parameter changes due at t_k are applied to the controller (0 and 1: the loop's
//      before_outputs);
//   2. the plant publishes /clock, Pose, Velocity, Imu for x(t_k);
//   3. on every `controller_divider`-th tick the controller steps on the tick and publishes a command
//      (after_outputs; a command lost to an injected fault is not waited for: the plant holds);
//   4. the plant latches the command in effect (zero-order hold, after the configured delay);
//   5. the tick is recorded (after_latch) (state at t_k, command over [t_k, t_k+1), the controller's latest status
//      as received on its status topic);
//   6. the plant integrates to t_k+1 (not after the last tick).
// Same inputs, same bytes: nothing here reads a wall clock or an unseeded random source (the plant's
// noise comes from the scenario's seed, sim/realism.hpp).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "sim/clock.hpp"
#include "sim/controller_node.hpp"
#include "sim/faults.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/lockstep_core.hpp"
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
  const model::RotorVector& latched_command;  ///< rotor command acting over [t_k, t_k+1) [rad/s]
  const msg::ControllerStatus& status;        ///< the controller's latest step, as published
};

class Simulation {
 public:
  /// Throws std::invalid_argument when a scheduled parameter is refused by the controller.
  Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle, const model::State& initial,
             const control::ControllerConfig& controller, std::vector<ScheduledParameter> schedule);

  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Runs ticks 0..duration_ticks, calling on_tick for each.
  void run(const std::function<void(const TickRecord&)>& on_tick);

  /// Steps 0-6 above for tick k, without recording: what run() does per tick. Call with k = 0, 1, ...
  /// in order (a swarm advances many simulations tick by tick, or block by block).
  void tick(Tick k) { loop_.tick(k); }
  /// The same, calling on_tick with the tick's record after the latch (step 5).
  void tick(Tick k, const std::function<void(const TickRecord&)>& on_tick);
  /// The current state, the command acting over [t_k, t_k+1) and the latest status, after tick k's
  /// latch (for recorders that do not go through run()).
  TickRecord record(Tick k) const;

  const PlantNode& plant() const { return plant_; }
  /// The bus the nodes talk on, for observers such as recorders (subscribe before run()).
  Transport& transport() { return transport_; }
  /// Messages lost to injected faults on `topic` so far.
  std::uint64_t dropped(const std::string& topic) const { return transport_.dropped(topic); }
  const ControllerNode& controller() const { return controller_; }
  /// The controller node, to set its parameters (setpoints, gains) between ticks.
  ControllerNode& controller() { return controller_; }

  /// Rotor speeds [rad/s] published on the motor command topic on every control tick instead of
  /// stepping the controller (which then neither runs nor publishes a status), until cleared with
  /// nullopt. The plant checks and latches them as any command (a stepping front end flying its own
  /// commands).
  void override_command(const std::optional<model::RotorVector>& omega_rad_s);
  /// The same at any command level (control/command_level.hpp): the plant's inner loops fly it.
  void override_level_command(const std::optional<control::LevelCommand>& command);

 private:
  /// The lockstep loop's hooks for this run (inlined: the loop's type names them).
  struct Hooks {
    Simulation* s;
    static bool main_thread_due(Tick /*k*/) { return false; }
    bool before_outputs(Tick k) const {
      s->transport_.advance_to(k);  // messages held back by injected delay are delivered now
      s->schedule_.apply(s->controller_, s->config_.plant.clock.ns(k));
      return true;
    }
    void after_outputs(Tick k) const {
      if (k % s->config_.controller_divider != 0) return;
      if (s->override_) {
        s->publish_override(k);
      } else {
        s->controller_.step(s->config_.plant.clock.ns(k), s->control_dt_s_);
      }
    }
    void after_latch(std::size_t /*i*/, Tick k) const {
      if (s->on_tick_) (*s->on_tick_)(s->record(k));
    }
    static void on_timeout(std::size_t /*i*/, Tick /*k*/) {}
    static void on_resume(Tick /*k*/) {}
    static bool status_awaited(std::size_t /*i*/) { return false; }
    static std::int64_t status_stamp_ns(std::size_t /*i*/) { return -1; }
  };

  void publish_override(Tick k);

  SimulationConfig config_;
  InProcessTransport transport_;
  PlantNode plant_;
  ControllerNode controller_;
  ParameterSchedule schedule_;
  double control_dt_s_;
  msg::ControllerStatus status_;  ///< the last status delivered, when faults may lose or delay statuses
  const msg::ControllerStatus* delivered_status_ = nullptr;          ///< status_, or the controller's own
  const std::function<void(const TickRecord&)>* on_tick_ = nullptr;  ///< while run() or tick(k, f)
  bool override_ = false;                                            ///< override_command() is in force
  Publisher<msg::Float64MultiArray> override_pub_;                   ///< advertised on first use
  msg::Float64MultiArray override_msg_;
  SynchronousHost host_;
  LockstepCore<PlantNode, Hooks, SynchronousHost, true> loop_;
};

}  // namespace quadcosim::sim
