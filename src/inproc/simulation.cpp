#include "inproc/simulation.hpp"

#include <stdexcept>

namespace quadcosim::inproc {

namespace {
bool faulty(const sim::FaultConfig& faults, const std::string& topic) {
  const auto f = faults.topics.find(topic);
  return f != faults.topics.end() && f->second.active();
}
}  // namespace

Simulation::Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle,
                       const model::State& initial, const control::ControllerConfig& controller,
                       std::vector<sim::ScheduledParameter> schedule)
    : config_(config),
      plant_(transport_, sim::Topics::for_namespace(config.ns), vehicle, config.plant, initial),
      controller_(transport_, sim::Topics::for_namespace(config.ns), controller) {
  transport_.set_faults(config.faults);
  const sim::Topics topics = sim::Topics::for_namespace(config.ns);
  if (faulty(config.faults, topics.controller_status)) {
    // Statuses may be lost or late: record the last one delivered.
    transport_.subscribe<msg::ControllerStatus>(topics.controller_status,
                                                [this](const msg::ControllerStatus& m) { status_ = m; });
    delivered_status_ = &status_;
  } else {
    // Every status is delivered as it is published: the last one delivered is the controller's own
    // (no copy per control step).
    delivered_status_ = &controller_.status();
  }

  const sim::TickClock& clock = config_.plant.clock;
  drivers::LockstepOptions o;
  o.clock = clock;
  o.duration_ticks = config_.duration_ticks;
  o.controller_divider = config_.controller_divider;
  o.timeout_ns = 0;  // what is not in when the outputs return will not come this tick: hold
  o.on_timeout = drivers::TimeoutPolicy::kHold;
  o.ticks_on_delivery = false;
  o.record_round_trips = false;
  drivers::LockstepHooks h;
  h.after_latch = [this](std::size_t, sim::Tick k) {
    if (*on_tick_) (*on_tick_)(record(k));
  };
  if (faulty(config.faults, topics.pose) || faulty(config.faults, topics.velocity) ||
      faulty(config.faults, topics.imu)) {
    tick_schedule_.emplace(std::move(schedule), clock);
    const double dt_s = clock.period_s() * config_.controller_divider;
    h.before_outputs = [this, clock](sim::Tick k) {
      transport_.advance_to(k);  // messages held back by injected delay are delivered now
      tick_schedule_->apply(controller_, clock.ns(k));
      return true;
    };
    h.after_outputs = [this, clock, dt_s](sim::Tick k) {
      if (k % config_.controller_divider == 0) controller_.step(clock.ns(k), dt_s);
    };
  } else {
    h.before_outputs = [this](sim::Tick k) {
      transport_.advance_to(k);
      return true;
    };
    controller_driver_.emplace(std::vector<drivers::DrivenController>{{&controller_, std::move(schedule)}}, clock,
                               config_.controller_divider, host_);
  }
  driver_.emplace(std::vector<drivers::DrivenPlant>{{&plant_, {}, {}}}, o, std::move(h), host_);
}

TickRecord Simulation::record(sim::Tick k) const {
  return TickRecord{k, config_.plant.clock.seconds(k), plant_.state(), plant_.applied_command(), *delivered_status_};
}

void Simulation::run_ticks(sim::Tick last, const std::function<void(const TickRecord&)>& on_tick) {
  on_tick_ = &on_tick;
  struct Clear {  // also when a hook throws
    const std::function<void(const TickRecord&)>*& f;
    ~Clear() { f = nullptr; }
  } clear{on_tick_};
  // The host never stops a run and holds instead of timing out: every tick up to `last` runs.
  driver_->run_until(last);
}

void Simulation::run(const std::function<void(const TickRecord&)>& on_tick) {
  run_ticks(config_.duration_ticks, on_tick);
}

}  // namespace quadcosim::inproc
