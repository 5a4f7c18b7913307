#include "sim/lockstep_stepper.hpp"

namespace quadcosim::sim {

LockstepStepper::LockstepStepper(ControllerNode& node, std::vector<ScheduledParameter> schedule, const TickClock& clock,
                                 int controller_divider)
    : node_(node),
      schedule_(std::move(schedule), clock),
      plant_period_ns_(clock.period_ns),
      control_period_ns_(clock.period_ns * controller_divider),
      dt_s_(static_cast<double>(control_period_ns_) / 1e9) {
  node_.on_sample([this] { react(); });
}

LockstepStepper::~LockstepStepper() { node_.on_sample(nullptr); }

void LockstepStepper::react() {
  const std::int64_t s = node_.synchronized_stamp_ns();
  if (s < 0 || s % control_period_ns_ != 0 || !node_.core().sensors_complete(s, plant_period_ns_)) return;
  if (s > node_.last_step_ns()) {
    schedule_.apply(node_, s);
    node_.step(s, dt_s_);
  } else if (s == node_.last_step_ns()) {
    node_.republish();  // the plant asked again for a tick already answered
  }
}

}  // namespace quadcosim::sim
