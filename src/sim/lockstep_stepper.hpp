// A controller node in lockstep over DDS: it steps once per complete sensor sample (Pose, Velocity
// and Imu of one plant tick, and the extra sensors due at that tick) that falls on a control tick, on the sample's own
// time, after applying the parameter schedule due by then; a complete sample of a tick it has answered already (the
// plant published it again) is answered again with the same command and status. Hooked to the
// node's on_sample, so it reacts where the transport delivers, also on a DDS receive thread.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/clock.hpp"
#include "sim/controller_node.hpp"
#include "sim/parameter_schedule.hpp"

namespace quadcosim::sim {

class LockstepStepper {
 public:
  /// Hooks itself to `node` (not copyable or movable: the hook holds `this`).
  LockstepStepper(ControllerNode& node, std::vector<ScheduledParameter> schedule, const TickClock& clock,
                  int controller_divider);
  ~LockstepStepper();
  LockstepStepper(const LockstepStepper&) = delete;
  LockstepStepper& operator=(const LockstepStepper&) = delete;

  /// What the node's hook runs. Throws std::invalid_argument naming a scheduled parameter the
  /// node refused.
  void react();

 private:
  ControllerNode& node_;
  ParameterSchedule schedule_;
  std::int64_t plant_period_ns_;
  std::int64_t control_period_ns_;
  double dt_s_;
};

}  // namespace quadcosim::sim
