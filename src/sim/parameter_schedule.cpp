#include "sim/parameter_schedule.hpp"

#include <algorithm>
#include <stdexcept>

namespace quadcosim::sim {

ParameterSchedule::ParameterSchedule(std::vector<ScheduledParameter> schedule, const TickClock& clock)
    : schedule_(std::move(schedule)), clock_(clock) {
  std::stable_sort(schedule_.begin(), schedule_.end(), [](const auto& a, const auto& b) { return a.tick < b.tick; });
  next_due_ns_ = due_ns();
}

std::int64_t ParameterSchedule::due_ns() const {
  return next_ < schedule_.size() ? clock_.ns(schedule_[next_].tick) : std::numeric_limits<std::int64_t>::max();
}

void ParameterSchedule::apply_due(ControllerCore& core, std::int64_t now_ns) {
  while (next_due_ns_ <= now_ns) {
    const ScheduledParameter& p = schedule_[next_];
    if (std::string err = core.set_parameter(p.name, p.value); !err.empty()) {
      throw std::invalid_argument("scheduled parameter at t=" + std::to_string(clock_.seconds(p.tick)) +
                                  " s refused: " + err);
    }
    ++next_;
    next_due_ns_ = due_ns();
  }
}

}  // namespace quadcosim::sim
