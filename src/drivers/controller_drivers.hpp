// The controller side: one driver per pacing for one controller or many (a swarm's share), the
// same in-process and over DDS.
//
// Lockstep: each controller steps where its samples are delivered (sim::LockstepStepper: once per
// complete sample of a control tick, on the sample's time, after the schedule due by then; a
// repeated tick answered again), so over DDS, with delivery on arrival, answering a tick wakes no
// other thread; the host's thread only serves what else the host has (discovery, parameter
// services) until a stop.
//
// Real time: every controller steps on one wall-clock timer (control period / rate_factor), its
// data's age measured by arrival (the app sets ControllerNode::use_receipt_clock). Until a
// controller's first complete sensor sample it commands nothing (a controller restarted beside a
// flying plant must not send it the stale-data safety command before it has seen the vehicle);
// after that Algorithm 1 as everywhere: stale data -> the safety command. Its schedule is applied
// by the newest sample's simulated time.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "drivers/driver_host.hpp"
#include "sim/clock.hpp"
#include "sim/controller_node.hpp"
#include "sim/lockstep_stepper.hpp"
#include "sim/parameter_schedule.hpp"

namespace quadcosim::drivers {

/// One controller and the parameter changes scheduled for it.
struct DrivenController {
  sim::ControllerNode* node = nullptr;
  std::vector<sim::ScheduledParameter> schedule;
};

class LockstepControllerDriver {
 public:
  /// Hooks a LockstepStepper to each node (unhooked in the destructor).
  LockstepControllerDriver(std::vector<DrivenController> controllers, const sim::TickClock& clock,
                           int controller_divider, DriverHost& host);
  /// Steps on delivery until the host asks to stop. A scheduled parameter a node refuses ends it
  /// with std::invalid_argument (naming the change).
  void run();

 private:
  std::vector<std::unique_ptr<sim::LockstepStepper>> steppers_;
  DriverHost& host_;
};

struct RealtimeControllerHooks {
  /// Each wake-up of the timer [wall ns] (period jitter figures).
  std::function<void(std::int64_t)> on_wake;
  /// Controller i saw its first complete sensor sample, of simulated time stamp_ns.
  std::function<void(std::size_t, std::int64_t)> on_first_sample;
  /// Controller i switched to (true) or from the stale-data safety command at wall time now_ns.
  std::function<void(std::size_t, bool, std::int64_t)> on_safety;
};

class RealtimeControllerDriver {
 public:
  RealtimeControllerDriver(std::vector<DrivenController> controllers, const sim::TickClock& clock,
                           int controller_divider, double rate_factor, RealtimeControllerHooks hooks, DriverHost& host);
  /// Steps every period until the host asks to stop. Throws std::invalid_argument on a refused
  /// scheduled parameter.
  void run();

 private:
  struct Slot {
    sim::ControllerNode* node;
    sim::ParameterSchedule schedule;
    bool seen_vehicle = false;
    bool safety = false;
  };
  std::vector<Slot> controllers_;
  double dt_s_;
  std::int64_t wall_period_ns_;
  RealtimeControllerHooks hooks_;
  DriverHost& host_;
};

}  // namespace quadcosim::drivers
