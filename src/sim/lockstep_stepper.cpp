#include "sim/lockstep_stepper.hpp"

#include <algorithm>
#include <stdexcept>

namespace quadcosim::sim {

ParameterSchedule::ParameterSchedule(std::vector<ScheduledParameter> schedule, const TickClock& clock)
    : schedule_(std::move(schedule)), clock_(clock) {
  std::stable_sort(schedule_.begin(), schedule_.end(), [](const auto& a, const auto& b) { return a.tick < b.tick; });
  next_ = schedule_.begin();
}

void ParameterSchedule::apply(ControllerNode& node, std::int64_t now_ns) {
  for (; next_ != schedule_.end() && clock_.ns(next_->tick) <= now_ns; ++next_) {
    if (std::string err = node.set_parameter(next_->name, next_->value); !err.empty()) {
      throw std::invalid_argument("scheduled parameter refused: " + err);
    }
  }
}

LockstepStepper::LockstepStepper(ControllerNode& node, std::vector<ScheduledParameter> schedule,
                                 const TickClock& clock, int controller_divider)
    : node_(node),
      schedule_(std::move(schedule), clock),
      control_period_ns_(clock.period_ns * controller_divider),
      dt_s_(static_cast<double>(control_period_ns_) / 1e9) {
  node_.on_sample([this] { react(); });
}

LockstepStepper::~LockstepStepper() { node_.on_sample(nullptr); }

void LockstepStepper::react() {
  const std::int64_t s = node_.synchronized_stamp_ns();
  if (s < 0 || s % control_period_ns_ != 0) return;
  if (s > node_.last_step_ns()) {
    schedule_.apply(node_, s);
    node_.step(s, dt_s_);
  } else if (s == node_.last_step_ns()) {
    node_.republish();  // the plant asked again for a tick already answered
  }
}

}  // namespace quadcosim::sim
