#include "sim/simulation.hpp"

#include <algorithm>
#include <stdexcept>

namespace quadcosim::sim {

Simulation::Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle,
                       const model::State& initial, const control::ControllerConfig& controller,
                       std::vector<ScheduledParameter> schedule)
    : config_(config),
      plant_(transport_, Topics::for_namespace(config.ns), vehicle, config.plant, initial),
      controller_(transport_, Topics::for_namespace(config.ns), controller),
      schedule_(std::move(schedule)) {
  transport_.set_faults(config.faults);
  transport_.subscribe<msg::ControllerStatus>(
      Topics::for_namespace(config.ns).controller_status,
      [this](const msg::ControllerStatus& m) { status_ = m; });
  std::stable_sort(schedule_.begin(), schedule_.end(),
                   [](const auto& a, const auto& b) { return a.tick < b.tick; });
  next_event_ = schedule_.cbegin();
  control_dt_s_ = config_.plant.clock.period_s() * config_.controller_divider;
}

void Simulation::begin_tick(Tick k) {
  const TickClock& clock = config_.plant.clock;
  transport_.advance_to(k);  // messages held back by injected delay are delivered now
  for (; next_event_ != schedule_.cend() && next_event_->tick <= k; ++next_event_) {
    if (std::string err = controller_.set_parameter(next_event_->name, next_event_->value); !err.empty()) {
      throw std::invalid_argument("scheduled parameter at t=" + std::to_string(clock.seconds(k)) +
                                  " s refused: " + err);
    }
  }
  plant_.publish_outputs(k);
  if (k % config_.controller_divider == 0) controller_.step(clock.ns(k), control_dt_s_);
  plant_.latch_command(k);
}

TickRecord Simulation::record(Tick k) const {
  return TickRecord{k, config_.plant.clock.seconds(k), plant_.state(), plant_.applied_command(), status_};
}

void Simulation::run(const std::function<void(const TickRecord&)>& on_tick) {
  for (Tick k = 0; k <= config_.duration_ticks; ++k) {
    begin_tick(k);
    if (on_tick) on_tick(record(k));
    end_tick(k);
  }
}

}  // namespace quadcosim::sim
