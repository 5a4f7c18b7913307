#include "sim/simulation.hpp"

namespace quadcosim::sim {

Simulation::Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle,
                       const model::State& initial, const control::ControllerConfig& controller,
                       std::vector<ScheduledParameter> schedule)
    : config_(config),
      plant_(transport_, Topics::for_namespace(config.ns), vehicle, config.plant, initial),
      controller_(transport_, Topics::for_namespace(config.ns), controller),
      schedule_(std::move(schedule), config.plant.clock) {
  transport_.set_faults(config.faults);
  const std::string status_topic = Topics::for_namespace(config.ns).controller_status;
  if (const auto f = config.faults.topics.find(status_topic); f != config.faults.topics.end() && f->second.active()) {
    // Statuses may be lost or late: record the last one delivered.
    transport_.subscribe<msg::ControllerStatus>(status_topic, [this](const msg::ControllerStatus& m) { status_ = m; });
    delivered_status_ = &status_;
  } else {
    // Every status is delivered as it is published: the last one delivered is the controller's own
    // (no copy per control step).
    delivered_status_ = &controller_.status();
  }
  control_dt_s_ = config_.plant.clock.period_s() * config_.controller_divider;
}

void Simulation::begin_tick(Tick k) {
  const TickClock& clock = config_.plant.clock;
  transport_.advance_to(k);  // messages held back by injected delay are delivered now
  schedule_.apply(controller_, clock.ns(k));
  plant_.publish_outputs(k);
  if (k % config_.controller_divider == 0) controller_.step(clock.ns(k), control_dt_s_);
  plant_.latch_command(k);
}

TickRecord Simulation::record(Tick k) const {
  return TickRecord{k, config_.plant.clock.seconds(k), plant_.state(), plant_.latched_command(), *delivered_status_};
}

void Simulation::run(const std::function<void(const TickRecord&)>& on_tick) {
  for (Tick k = 0; k <= config_.duration_ticks; ++k) {
    begin_tick(k);
    if (on_tick) on_tick(record(k));
    end_tick(k);
  }
}

}  // namespace quadcosim::sim
