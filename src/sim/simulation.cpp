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
}

void Simulation::run(const std::function<void(const TickRecord&)>& on_tick) {
  const TickClock& clock = config_.plant.clock;
  const double control_dt_s = clock.period_s() * config_.controller_divider;
  auto next_event = schedule_.begin();
  for (Tick k = 0; k <= config_.duration_ticks; ++k) {
    transport_.advance_to(k);
    for (; next_event != schedule_.end() && next_event->tick <= k; ++next_event) {
      if (std::string err = controller_.set_parameter(next_event->name, next_event->value); !err.empty()) {
        throw std::invalid_argument("scheduled parameter at t=" + std::to_string(clock.seconds(k)) +
                                    " s refused: " + err);
      }
    }
    plant_.publish_outputs(k);
    if (k % config_.controller_divider == 0) controller_.step(clock.ns(k), control_dt_s);
    plant_.latch_command(k);
    if (on_tick) {
      on_tick(TickRecord{k, clock.seconds(k), plant_.state(), plant_.applied_command(), status_});
    }
    if (k < config_.duration_ticks) plant_.integrate(k);
  }
}

}  // namespace quadcosim::sim
