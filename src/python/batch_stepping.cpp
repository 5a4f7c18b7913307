// python/batch_class.hpp: stepping a Batch's vehicles (the worker pool over chunks of them; a lean
// vehicle's tick as the plant and controller nodes take it; the rows Python reads, written as they step).
#include "python/batch_class.hpp"

namespace py = pybind11;

namespace quadcosim::python {

void Batch::step(const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& omega_cmd,
                 int periods) {
  if (periods < 1) {
    throw py::value_error("Batch.step: periods = " + std::to_string(periods) + ": expected at least 1");
  }
  if (plant_only_ && !omega_cmd) {
    throw py::value_error("Batch.step: this batch is plant_only (no controllers): give omega_cmd, an (n, " +
                          std::to_string(rotors_) + ") array of rotor speeds [rad/s]; nothing was stepped");
  }
  if (omega_cmd && level_ != control::CommandLevel::kRotorSpeeds) {
    check_level_commands(*omega_cmd);
  } else if (omega_cmd) {
    const std::size_t r = rotors_;
    if (omega_cmd->ndim() != 2 || omega_cmd->shape(0) != static_cast<py::ssize_t>(n_) ||
        omega_cmd->shape(1) != static_cast<py::ssize_t>(r)) {
      throw py::value_error("Batch.step: omega_cmd: expected an array of shape (" + std::to_string(n_) + ", " +
                            std::to_string(r) + ") (" + std::to_string(r) +
                            " rotor speeds [rad/s] per vehicle), got shape " +
                            py::repr(omega_cmd->attr("shape")).cast<std::string>() + "; nothing was stepped");
    }
    const double* c = omega_cmd->data();
    for (std::size_t j = 0; j < r * n_; ++j) {
      if (!std::isfinite(c[j])) {
        throw py::value_error("Batch.step: omega_cmd[" + std::to_string(j / r) + ", " + std::to_string(j % r) +
                              "] = " + py::repr(py::float_(c[j])).cast<std::string>() +
                              ": rotor speeds must be finite; nothing was stepped");
      }
    }
  }
  const bool bypass = omega_cmd.has_value();
  const double* c = bypass ? omega_cmd->data() : nullptr;
  py::gil_scoped_release release;
  std::lock_guard lock(mutex_);
  if (bypass) std::copy(c, c + command_width_ * n_, omega_cmd_.begin());
  if (lean_vehicles_) {
    pool_.run(chunks(), [&](std::uint32_t c) {
      const std::size_t last = std::min(n_, (c + 1) * kChunk);
      for (std::size_t i = c * kChunk; i < last; ++i) {
        if (i + 1 < last) prefetch(lean_[i + 1]);
        step_lean(i, bypass, periods);
      }
    });
    return;
  }
  pool_.run(chunks(), [&](std::uint32_t c) {
    const std::size_t last = std::min(n_, (c + 1) * kChunk);
    for (std::size_t i = c * kChunk; i < last; ++i) {
      if (i + 1 < last) prefetch(*vehicles_[i + 1].sim);
      step_vehicle(i, bypass, periods);
    }
  });
}

void Batch::check_level_commands(const py::array_t<double, py::array::c_style | py::array::forcecast>& cmd) const {
  // rotor_thrusts is refused for a vehicle without four rotors when the batch is made.
  const std::string_view level = control::to_string(level_);
  const auto& fields = control::setpoint_fields(level_);
  if (cmd.ndim() != 2 || cmd.shape(0) != static_cast<py::ssize_t>(n_) || cmd.shape(1) != 4) {
    std::string names;
    for (std::string_view f : fields) names += (names.empty() ? "" : ", ") + std::string(f);
    throw py::value_error("Batch.step: " + std::string(level) + " commands: expected an array of shape (" +
                          std::to_string(n_) + ", 4) (" + names + " per vehicle), got shape " +
                          py::repr(cmd.attr("shape")).cast<std::string>() + "; nothing was stepped");
  }
  const double* c = cmd.data();
  for (std::size_t j = 0; j < 4 * n_; ++j) {
    if (!std::isfinite(c[j])) {
      throw py::value_error("Batch.step: " + std::string(level) + " commands[" + std::to_string(j / 4) + ", " +
                            std::to_string(j % 4) + "] (" + std::string(fields[j % 4]) +
                            ") = " + py::repr(py::float_(c[j])).cast<std::string>() +
                            ": commands must be finite; nothing was stepped");
    }
  }
}

void Batch::step_vehicle(std::size_t i, bool bypass, int periods) {
  Vehicle& v = vehicles_[i];
  if (bypass) {
    const double* c = &omega_cmd_[command_width_ * i];
    if (level_ == control::CommandLevel::kRotorSpeeds) {
      v.sim->override_command(
          model::RotorVector(Eigen::Map<const model::RotorVector>(c, static_cast<Eigen::Index>(rotors_))));
    } else {
      v.sim->override_level_command(control::LevelCommand{level_, model::Vector4(c[0], c[1], c[2], c[3])});
    }
  }
  const int ticks = v.scenario->simulation.controller_divider * periods;
  const sensors::Suite* extra = v.sim->plant().extra_sensors();
  const sim::TickClock& clock = v.scenario->simulation.plant.clock;
  for (int j = 0; j < ticks; ++j) {
    const sim::Tick k = v.next_tick++;
    v.sim->tick(k);
    if (extra) write_sensors(i, *extra, k, stamp_s(msg::Time::from_ns(clock.ns(k))));
  }
  if (bypass) v.sim->override_command(std::nullopt);
  fill_state(i);
}

void Batch::step_lean(std::size_t i, bool bypass, int periods) {
  Vehicle& v = vehicles_[i];
  LeanVehicle& L = lean_[i];
  const io::Scenario& s = *v.scenario;
  const sim::PlantOptions& o = s.simulation.plant;
  const int divider = s.simulation.controller_divider;
  const double control_dt_s = o.clock.period_s() * divider;  // as Simulation's
  const std::int64_t watchdog_ns = o.watchdog_ticks > 0 ? o.clock.ns(o.watchdog_ticks) : 0;
  sim::ControllerCore* const controller = L.controller ? &*L.controller : nullptr;
  thread_local msg::Float64MultiArray command;  // the command message, as the controller node or Simulation sends it
  if (bypass) {
    command.data.assign(&omega_cmd_[command_width_ * i], &omega_cmd_[command_width_ * i] + command_width_);
    // As Simulation::override_level_command sends it: the level named in the layout (none for speeds).
    msg::set_command_level(command, control::to_string(level_));
  } else {
    command.data.resize(rotors_);
  }
  thread_local msg::PoseStamped pose;  // the samples, as the plant node publishes them
  thread_local msg::TwistStamped twist;
  thread_local msg::Imu imu;
  const sim::Tick end = v.next_tick + static_cast<sim::Tick>(divider) * periods;
  for (sim::Tick k = v.next_tick; k < end; ++k) {
    v.next_tick = k + 1;  // as step_vehicle counts a tick begun (one whose controller threw, say)
    // Scheduled parameter changes (Simulation's before_outputs).
    if (L.schedule) L.schedule->apply(*controller, o.clock.ns(k));
    // Outputs and sensors (PlantNode::publish_outputs), taken in by the controller node's core and
    // written into the rows as the whole vehicle's subscriptions write them.
    const model::Outputs y = L.plant.outputs(o.clock, k);
    const msg::Time time = msg::Time::from_ns(o.clock.ns(k));
    const double stamp = stamp_s(time);
    if (controller || L.plant.has_realism()) {
      const sim::PlantRealism::Due due = L.plant.sense(k, y, time, pose, twist, imu);
      if (due.pose) {
        if (controller) controller->take_pose(pose);
        write_pose(i, stamp, pose.position, pose.orientation);
      }
      if (due.velocity) {
        if (controller) controller->take_velocity(twist);
        write_velocity(i, stamp, twist.linear, twist.angular);
      }
      if (due.imu) {
        if (controller) controller->take_imu(imu);
        write_imu(i, stamp, imu.orientation, imu.angular_velocity, imu.linear_acceleration);
      }
    } else {  // plant_only, exact sensors: the rows straight from the outputs (no messages to make)
      pose_t_[i] = velocity_t_[i] = imu_t_[i] = stamp;
      set3(pose_p_, i, y.p_W.x(), y.p_W.y(), y.p_W.z());
      set4(pose_q_, i, y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z());
      set3(velocity_v_, i, y.v_W.x(), y.v_W.y(), y.v_W.z());
      set3(velocity_w_, i, y.w_B.x(), y.w_B.y(), y.w_B.z());
      set4(imu_q_, i, y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z());
      set3(imu_w_, i, y.w_B.x(), y.w_B.y(), y.w_B.z());
      set3(imu_a_, i, y.specific_force_B.x(), y.specific_force_B.y(), y.specific_force_B.z());
    }
    if (L.plant.sense_extra(k, y)) {
      const sensors::Suite& extra = *L.plant.extra_sensors();
      write_sensors(i, extra, k, stamp);
      // Taken in by the controller as the node takes them from the channels' messages.
      if (controller) {
        sensors::for_each_configured(o.realism.extra_sensors, [&]<class Kind>(const typename Kind::Config& c) {
          if (extra.due<Kind>(k)) controller->take<Kind>(sim::as_read<Kind>(extra.slot<Kind>()->sample, c), time);
        });
      }
    }
    // On control ticks the controller's step or the command given (Simulation's after_outputs), taken
    // in as PlantNode::on_command takes it (every command answers its own tick).
    if (k % divider == 0) {
      if (!bypass) {
        const sim::ControllerCore::Begun begun = controller->begin_step(o.clock.ns(k));
        controller->decide(begun.safety, control_dt_s);
        sim::write_command(controller->output(), command);  // its rotor speeds, or its level's setpoint
      }
      L.plant.take_command(k, o.command_delay_ticks, command);
    }
    // The latch (PlantNode::latch_command): the newest due command, then the watchdog.
    L.watchdog = L.plant.latch(k, L.plant.command_age_ns(o.clock, k), watchdog_ns, o.watchdog_policy);
    // The integration to t_k+1 (PlantNode::integrate).
    L.plant.integrate(o.clock, k, o.substeps);
  }
  fill_state(i);
}

void Batch::write_sensors(std::size_t i, const sensors::Suite& suite, sim::Tick k, double stamp) {
  sensors::for_each_kind([&]<class Kind>() {
    std::optional<SensorRows>& rows = sensor_rows_[sensors::kind_index<Kind>()];
    if (!rows || !suite.due<Kind>(k)) return;
    rows->t[i] = stamp;
    sensors::write_sample<Kind>(suite.slot<Kind>()->sample, &rows->values[i * static_cast<std::size_t>(rows->width)]);
  });
}

void Batch::write_pose(std::size_t i, double t, const msg::Vector3& p, const msg::Quaternion& q) {
  pose_t_[i] = t;
  set3(pose_p_, i, p.x, p.y, p.z);
  set4(pose_q_, i, q.w, q.x, q.y, q.z);
}

void Batch::write_velocity(std::size_t i, double t, const msg::Vector3& v, const msg::Vector3& w) {
  velocity_t_[i] = t;
  set3(velocity_v_, i, v.x, v.y, v.z);
  set3(velocity_w_, i, w.x, w.y, w.z);
}

void Batch::write_imu(std::size_t i, double t, const msg::Quaternion& q, const msg::Vector3& w, const msg::Vector3& a) {
  imu_t_[i] = t;
  set4(imu_q_, i, q.w, q.x, q.y, q.z);
  set3(imu_w_, i, w.x, w.y, w.z);
  set3(imu_a_, i, a.x, a.y, a.z);
}

void Batch::StateRow::tick(const sim::RecordedTick& t) {
  const model::State& x = t.state;
  const std::size_t i = i_;
  set3(b_->p_, i, x.p_W.x(), x.p_W.y(), x.p_W.z());
  set3(b_->v_, i, x.v_W.x(), x.v_W.y(), x.v_W.z());
  set4(b_->q_, i, x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z());
  set3(b_->w_, i, x.w_B.x(), x.w_B.y(), x.w_B.z());
  const model::RotorVector& c = t.command;
  if (b_->rotors_ == 4) {
    set4(b_->omega_, i, x.omega_rad_s[0], x.omega_rad_s[1], x.omega_rad_s[2], x.omega_rad_s[3]);
    set4(b_->command_, i, c[0], c[1], c[2], c[3]);
  } else {
    const std::size_t r = b_->rotors_;
    for (std::size_t k = 0; k < r; ++k) {
      b_->omega_[r * i + k] = x.omega_rad_s[static_cast<Eigen::Index>(k)];
      b_->command_[r * i + k] = c[static_cast<Eigen::Index>(k)];
    }
  }
  b_->t_[i] = t.t_s;
}

void Batch::fill_state(std::size_t i) {
  const Vehicle& v = vehicles_[i];
  if (v.sim) {
    record(i, v.next_tick, v.sim->plant().state(), v.sim->plant().latched_command(), v.sim->plant().watchdog_active());
  } else {
    record(i, v.next_tick, lean_[i].plant.state(), lean_[i].plant.latched(), lean_[i].watchdog);
  }
}

}  // namespace quadcosim::python
