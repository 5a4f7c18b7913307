#include "sim/simulation.hpp"

namespace quadcosim::sim {

namespace {
LockstepOptions lockstep_options(const SimulationConfig& config) {
  LockstepOptions o;
  o.clock = config.plant.clock;
  o.duration_ticks = config.duration_ticks;
  o.controller_divider = config.controller_divider;
  return o;
}

/// Clears the on-tick pointer when the run ends (also when a hook throws).
struct ClearOnTick {
  const std::function<void(const TickRecord&)>*& f;
  ~ClearOnTick() { f = nullptr; }
};
}  // namespace

Simulation::Simulation(const SimulationConfig& config, const model::VehicleParams& vehicle, const model::State& initial,
                       const control::ControllerConfig& controller, std::vector<ScheduledParameter> schedule)
    : config_(config),
      plant_(transport_, Topics::for_namespace(config.ns), vehicle, config.plant, initial),
      controller_(transport_, Topics::for_namespace(config.ns), controller, {}, config.plant.realism.extra_sensors),
      schedule_(std::move(schedule), config.plant.clock),
      loop_({&plant_}, lockstep_options(config), Hooks{this}, host_) {
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

TickRecord Simulation::record(Tick k) const {
  return TickRecord{k, config_.plant.clock.seconds(k), plant_.state(), plant_.latched_command(), *delivered_status_};
}

void Simulation::run(const std::function<void(const TickRecord&)>& on_tick) {
  if (on_tick) on_tick_ = &on_tick;
  const ClearOnTick clear{on_tick_};
  loop_.run();  // the hooks never refuse a tick
}

void Simulation::tick(Tick k, const std::function<void(const TickRecord&)>& on_tick) {
  if (on_tick) on_tick_ = &on_tick;
  const ClearOnTick clear{on_tick_};
  loop_.tick(k);
}

void Simulation::override_command(const std::optional<model::RotorVector>& omega_rad_s) {
  if (!omega_rad_s) {
    override_level_command(std::nullopt);
    return;
  }
  if (omega_rad_s->size() == 4) {
    override_level_command(control::LevelCommand{control::CommandLevel::kRotorSpeeds, omega_rad_s->head<4>()});
    return;
  }
  // Another rotor count: its N speeds as they are (a level command holds four values).
  override_level_command(control::LevelCommand{control::CommandLevel::kRotorSpeeds, Eigen::Vector4d::Zero()});
  override_msg_.data.assign(omega_rad_s->data(), omega_rad_s->data() + omega_rad_s->size());
}

void Simulation::override_level_command(const std::optional<control::LevelCommand>& command) {
  override_ = command.has_value();
  if (!override_) return;
  if (!override_pub_) {
    override_pub_ = transport_.advertise<msg::Float64MultiArray>(Topics::for_namespace(config_.ns).motor_commands);
    override_msg_.dim = {{std::string(msg::command_label(0)), 4, 4}};  // the lockstep label first
  }
  override_msg_.data.assign(command->value.data(), command->value.data() + 4);
  msg::set_command_level(override_msg_, control::to_string(command->level));
}

void Simulation::publish_override(Tick k) {
  msg::write_command_label(override_msg_.dim[0].label, config_.plant.clock.ns(k));
  override_pub_.publish(override_msg_);
}

}  // namespace quadcosim::sim
