#include "drivers/realtime_plant_driver.hpp"

#include <algorithm>
#include <utility>

namespace quadcosim::drivers {

RealtimePlantDriver::RealtimePlantDriver(std::vector<sim::SteppablePlant*> plants, const RealtimeOptions& options,
                                         RealtimeHooks hooks, DriverHost& host)
    : plants_(std::move(plants)),
      o_(options),
      hooks_(std::move(hooks)),
      host_(host),
      wall_period_ns_(static_cast<std::int64_t>(static_cast<double>(o_.clock.period_ns) / o_.rate_factor)) {}

RealtimeResult RealtimePlantDriver::run() {
  next_wall_ns_ = host_.now_ns();
  for (sim::Tick k = 0; k <= o_.duration_ticks && !host_.stop_requested(); ++k) {
    if (hooks_.before_outputs && !hooks_.before_outputs(k)) return RealtimeResult::kRefused;
    for (sim::SteppablePlant* p : plants_) p->publish_outputs(k);
    pace();
    for (std::size_t i = 0; i < plants_.size(); ++i) {
      plants_[i]->latch_command(k);
      if (hooks_.after_latch) hooks_.after_latch(i, k);
      if (k < o_.duration_ticks) plants_[i]->integrate(k);
    }
    ++ticks_run_;
  }
  return host_.stop_requested() ? RealtimeResult::kStopped : RealtimeResult::kDone;
}

void RealtimePlantDriver::pace() {
  next_wall_ns_ += wall_period_ns_;
  std::int64_t now = host_.now_ns();
  while (!host_.stop_requested() && now < next_wall_ns_) {
    host_.wait(next_wall_ns_ - now, {});
    now = host_.now_ns();
  }
  const std::int64_t late = now - next_wall_ns_;
  max_late_ns_ = std::max(max_late_ns_, late);
  if (late > wall_period_ns_) ++late_ticks_;
}

}  // namespace quadcosim::drivers
