#include "drivers/controller_drivers.hpp"

#include <utility>

namespace quadcosim::drivers {

namespace {
constexpr std::int64_t kIdleWaitNs = 100'000'000;  ///< lockstep: how long the host's thread waits at once
}

LockstepControllerDriver::LockstepControllerDriver(std::vector<DrivenController> controllers,
                                                   const sim::TickClock& clock, int controller_divider,
                                                   DriverHost& host)
    : host_(host) {
  steppers_.reserve(controllers.size());
  for (DrivenController& c : controllers) {
    steppers_.push_back(
        std::make_unique<sim::LockstepStepper>(*c.node, std::move(c.schedule), clock, controller_divider));
  }
}

void LockstepControllerDriver::run() {
  host_.deliver_on_arrival(true);
  struct Off {
    DriverHost& h;
    ~Off() { h.deliver_on_arrival(false); }
  } off{host_};
  while (!host_.stop_requested()) host_.wait(kIdleWaitNs, {});
}

RealtimeControllerDriver::RealtimeControllerDriver(std::vector<DrivenController> controllers,
                                                   const sim::TickClock& clock, int controller_divider,
                                                   double rate_factor, RealtimeControllerHooks hooks, DriverHost& host)
    : dt_s_(static_cast<double>(clock.period_ns * controller_divider) / 1e9),
      wall_period_ns_(
          static_cast<std::int64_t>(static_cast<double>(clock.period_ns * controller_divider) / rate_factor)),
      hooks_(std::move(hooks)),
      host_(host) {
  controllers_.reserve(controllers.size());
  for (DrivenController& c : controllers) {
    controllers_.push_back(Slot{c.node, sim::ParameterSchedule(std::move(c.schedule), clock)});
  }
}

void RealtimeControllerDriver::run() {
  std::int64_t next = host_.now_ns();
  while (!host_.stop_requested()) {
    next += wall_period_ns_;
    host_.wait_until(next);
    if (hooks_.on_wake) hooks_.on_wake(host_.now_ns());
    for (std::size_t i = 0; i < controllers_.size(); ++i) {
      Slot& c = controllers_[i];
      if (!c.seen_vehicle) {
        if (c.node->synchronized_stamp_ns() < 0) continue;
        c.seen_vehicle = true;
        if (hooks_.on_first_sample) hooks_.on_first_sample(i, c.node->synchronized_stamp_ns());
      }
      c.schedule.apply(*c.node, c.node->newest_stamp_ns());
      const std::int64_t now = host_.now_ns();
      if (c.node->step(now, dt_s_).safety != c.safety) {
        c.safety = !c.safety;
        if (hooks_.on_safety) hooks_.on_safety(i, c.safety, now);
      }
    }
  }
}

}  // namespace quadcosim::drivers
