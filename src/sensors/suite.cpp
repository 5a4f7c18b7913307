#include "sensors/suite.hpp"

#include <algorithm>

namespace quadcosim::sensors {

Suite::Suite(const SensorSet& set, std::uint64_t seed, std::string_view vehicle, std::int64_t period_ns)
    : period_ns_(period_ns) {
  int depth = 0;
  const double period_s = static_cast<double>(period_ns) / 1e9;
  for_each_configured(set, [&]<class Kind>(const typename Kind::Config& config) {
    const model::Rng rng(model::stream_seed(seed, vehicle, Kind::kName));
    std::get<std::optional<Slot<Kind>>>(slots_).emplace(Slot<Kind>{Kind::make(config, rng, period_s), {}, -1});
    depth = std::max(depth, 1 + config.timing.latency_ticks);
  });
  history_.resize(static_cast<std::size_t>(depth));
}

bool Suite::step(std::int64_t k, const model::Outputs& y) {
  if (history_.empty()) return false;
  const auto depth = static_cast<std::int64_t>(history_.size());
  const bool first_visit = k != last_tick_;
  if (first_visit) {
    last_tick_ = k;
    history_[static_cast<std::size_t>(k % depth)] = y;
  }
  bool any = false;
  for_each_kind([&]<class Kind>() {
    auto& s = std::get<std::optional<Slot<Kind>>>(slots_);
    if (!s) return;
    const Timing& timing = s->model.config().timing;
    if (k % timing.divider != 0) return;
    any = true;
    if (s->tick == k) return;  // drawn on an earlier visit of k
    const std::int64_t measured = std::max<std::int64_t>(k - timing.latency_ticks, 0);
    const double measured_t_s = static_cast<double>(measured * period_ns_) / 1e9;  // as sim::TickClock::seconds
    s->sample = Kind::measure(s->model, history_[static_cast<std::size_t>(measured % depth)], measured_t_s);
    s->tick = k;
  });
  return any;
}

}  // namespace quadcosim::sensors
