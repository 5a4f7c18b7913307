#include "sim/controller_node.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include <fmt/format.h>

#include "model/attitude.hpp"
#include "sim/controller_thread.hpp"

namespace quadcosim::sim {

ControllerNode::ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config)
    : vehicle_(config.vehicle),
      trajectory_(config.trajectory),
      trajectory_offset_W_(config.trajectory_offset_W),
      settings_(config.node),
      controller_(config.controller ? config.controller->clone() : nullptr) {
  if (!controller_)
    throw std::invalid_argument("ControllerNode: the config has no controller (controllers::make_config)");
  log_ = [](const std::string& line) { std::cerr << line << '\n'; };
  output_.outputs.assign(controller_->output_names().size(), 0.0);
  status_.controller = controller_->type();
  status_.output_names.assign(controller_->output_names().begin(), controller_->output_names().end());
  status_.outputs = output_.outputs;
  status_pub_ = transport.advertise<msg::ControllerStatus>(topics.controller_status);
  command_pub_ = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  command_msg_.data.resize(4);
  command_msg_.dim = {{"", 4, 4}};
  // The callbacks capture only the node (the topic names are members): the transport stores them in
  // place, not in a heap block of their own read on every sample.
  pose_topic_ = topics.pose;
  velocity_topic_ = topics.velocity;
  imu_topic_ = topics.imu;
  transport.subscribe<msg::PoseStamped>(topics.pose, [this](const msg::PoseStamped& m) {
    if (!accept(check_pose(m, pose_stamp_ns_), pose_topic_, pose_backwards_)) return;
    observation_.p_W = {m.position.x, m.position.y, m.position.z};
    pose_stamp_ns_ = m.header.stamp.to_ns();
    pose_ref_ns_ = reference(pose_stamp_ns_);
    if (on_sample_) on_sample_();
  });
  transport.subscribe<msg::TwistStamped>(topics.velocity, [this](const msg::TwistStamped& m) {
    if (!accept(check_velocity(m, velocity_stamp_ns_), velocity_topic_, velocity_backwards_)) return;
    observation_.v_W = {m.linear.x, m.linear.y, m.linear.z};
    velocity_stamp_ns_ = m.header.stamp.to_ns();
    velocity_ref_ns_ = reference(velocity_stamp_ns_);
    if (on_sample_) on_sample_();
  });
  transport.subscribe<msg::Imu>(topics.imu, [this](const msg::Imu& m) {
    if (!accept(check_imu(m, imu_stamp_ns_), imu_topic_, imu_backwards_)) return;
    // Kept as received; turned into Euler angles when a step uses it (the plant publishes at twice
    // the control rate, so converting on arrival would do half the atan2s for nothing).
    observation_.q_WB = Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z);
    imu_pending_ = true;
    observation_.w_B = {m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z};
    observation_.specific_force_B = {m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z};
    imu_stamp_ns_ = m.header.stamp.to_ns();
    imu_ref_ns_ = reference(imu_stamp_ns_);
    if (on_sample_) on_sample_();
  });
}

bool ControllerNode::accept_refused(const SensorCheck& check, const std::string& topic, int& backwards) {
  if (check.fault == SensorFault::kStampBackwards && ++backwards > kStampRestartCount) {
    log_("controller: " + topic + ": " + std::to_string(kStampRestartCount) +
         " samples in a row older than the newest accepted; taking it that the sender's clock restarted (" +
         check.reason() + ")");
    backwards = 0;
    return true;
  }
  LogThrottle& counter = fault_log_[static_cast<int>(check.fault)];
  if (counter.count()) {
    log_("controller: " + topic + " message rejected, " + to_string(check.fault) + " (" + check.reason() + "); " +
         std::to_string(counter.total()) + " rejected for this reason so far (logged: 1st, then every 100th)");
  }
  return false;
}

namespace {
bool finite(const control::Observation& e) {
  return e.p_W.allFinite() && e.v_W.allFinite() && e.w_B.allFinite() && std::isfinite(e.roll_rad) &&
         std::isfinite(e.pitch_rad) && std::isfinite(e.yaw_rad);
}
}  // namespace

void ControllerNode::safety_output(const control::Reference& ref, control::ControllerOutput& out) const {
  // Algorithm 1, lines 3-5: every rotor at one speed; nothing else is decided. The attitude shown as
  // tracked is the reference's in attitude mode and level in position mode.
  const double w =
      settings_.safety == control::SafetyMode::kHover ? vehicle_.hover_omega_rad_s() : vehicle_.motor.omega_min_rad_s;
  out.omega_rad_s.setConstant(w);
  out.U.setZero();
  const bool attitude = ref.mode == control::Mode::kAttitude;
  out.roll_des_rad = attitude ? ref.roll_rad : 0.0;
  out.pitch_des_rad = attitude ? ref.pitch_rad : 0.0;
  out.yaw_des_rad = 0.0;
  out.attitude_error = std::numeric_limits<double>::quiet_NaN();
  out.rotor_saturated = {};
  out.tilt_saturated = false;
  std::fill(out.outputs.begin(), out.outputs.end(), std::numeric_limits<double>::quiet_NaN());
}

void ControllerNode::update_reference(std::int64_t now_ns) {
  if (trajectory_) {
    const trajectory::FlatOutput f = trajectory_->at(static_cast<double>(now_ns) / 1e9);
    reference_.mode = control::Mode::kPosition;
    reference_.p_W = f.p_W + trajectory_offset_W_;
    reference_.v_W = f.v_W;
    reference_.a_W = f.a_W;
    reference_.j_W = f.j_W;
    reference_.yaw_rad = f.yaw_rad;
    reference_.yaw_rate_rad_s = f.yaw_rate_rad_s;
    reference_.roll_rad = 0.0;
    reference_.pitch_rad = 0.0;
    return;
  }
  const control::Setpoint& sp = settings_.setpoint;
  reference_.mode = sp.mode;
  reference_.p_W = sp.p_des_W;
  reference_.v_W.setZero();
  reference_.a_W.setZero();
  reference_.j_W.setZero();
  reference_.yaw_rad = sp.yaw_des_rad;
  reference_.yaw_rate_rad_s = 0.0;
  reference_.roll_rad = sp.roll_des_rad;
  reference_.pitch_rad = sp.pitch_des_rad;
}

const control::ControllerOutput& ControllerNode::step(std::int64_t now_ns, double dt_s) {
  if (imu_pending_) {
    const model::Euler e = model::euler_from_quaternion(observation_.q_WB);
    observation_.roll_rad = e.roll_rad;
    observation_.pitch_rad = e.pitch_rad;
    observation_.yaw_rad = e.yaw_rad;
    imu_pending_ = false;
  }
  const std::int64_t oldest = std::min({pose_ref_ns_, velocity_ref_ns_, imu_ref_ns_});
  observation_.age_s =
      oldest == kNever ? std::numeric_limits<double>::infinity() : static_cast<double>(now_ns - oldest) / 1e9;
  const auto stamp = [](std::int64_t ns) { return ns == kNever ? std::int64_t{-1} : ns; };
  observation_.pose_stamp_ns = stamp(pose_stamp_ns_);
  observation_.velocity_stamp_ns = stamp(velocity_stamp_ns_);
  observation_.imu_stamp_ns = stamp(imu_stamp_ns_);

  // The status is stamped with simulated time: the step's time, or the newest sample's in real time.
  const std::int64_t sim_now_ns = receipt_clock_ ? std::max<std::int64_t>(newest_stamp_ns(), 0) : now_ns;
  update_reference(sim_now_ns);
  // Algorithm 1, lines 3-5, for every controller.
  const bool safety = !(observation_.age_s <= settings_.stale_limit_s) || !finite(observation_);
  if (thread_ && !safety) {
    step_on_thread(now_ns, sim_now_ns, dt_s);
    return output_;
  }
  const std::lock_guard lock(publish_mutex_);
  output_.safety = safety;
  if (output_.safety) {
    safety_output();
  } else {
    controller_->step(observation_, reference_, dt_s, output_);
  }
  publish(observation_, reference_, output_, sim_now_ns);
  last_step_ns_ = now_ns;
  return output_;
}

void ControllerNode::publish(const control::Observation& obs, const control::Reference& ref,
                             const control::ControllerOutput& out, std::int64_t sim_now_ns) {
  status_.header.stamp = msg::Time::from_ns(sim_now_ns);
  if (const char* mode = control::to_string(ref.mode); status_.mode != mode) status_.mode = mode;
  status_.setpoint = {ref.p_W.x(), ref.p_W.y(), ref.p_W.z(), out.roll_des_rad, out.pitch_des_rad, ref.yaw_rad};
  for (int i = 0; i < 3; ++i) status_.position_error[i] = ref.p_W[i] - obs.p_W[i];
  status_.yaw_error = model::wrap_pi(ref.yaw_rad - obs.yaw_rad);
  status_.attitude_error = out.attitude_error;
  for (int i = 0; i < 4; ++i) {
    status_.u[i] = out.U[i];
    status_.rotor_saturated[i] = out.rotor_saturated[i];
  }
  status_.tilt_saturated = out.tilt_saturated;
  status_.safety = out.safety;
  status_.rejected_non_finite = fault_log_[static_cast<int>(SensorFault::kNonFinite)].total();
  status_.rejected_bad_quaternion = fault_log_[static_cast<int>(SensorFault::kBadQuaternion)].total();
  status_.rejected_bad_stamp = fault_log_[static_cast<int>(SensorFault::kBadStamp)].total();
  status_.rejected_stamp_backwards = fault_log_[static_cast<int>(SensorFault::kStampBackwards)].total();
  status_.outputs = out.outputs;
  status_pub_.publish(status_);

  for (int i = 0; i < 4; ++i) command_msg_.data[i] = out.omega_rad_s[i];
  msg::write_command_label(command_msg_.dim[0].label, sim_now_ns);
  command_pub_.publish(command_msg_);
}

ControllerNode::~ControllerNode() {
  // The controller's thread first: a step's continuation uses the members below.
  controller_.reset();
}

void ControllerNode::run_controller_on_thread(ControllerThreading threading) {
  auto on_thread = std::make_unique<ControllerThread>(std::move(controller_), threading.thread_host);
  thread_ = on_thread.get();
  controller_ = std::move(on_thread);
  threading_ = std::move(threading);
}

std::optional<std::string> ControllerNode::controller_failure() const {
  const std::lock_guard lock(publish_mutex_);
  return failure_;
}

bool ControllerNode::controller_failed(const std::exception_ptr& error, std::int64_t sim_now_ns) {
  std::string what;
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "the controller's step threw something that is not a std::exception";
  }
  if (threading_.on_error == ControllerThreading::OnError::kStop) {
    if (!threading_.asynchronous) throw ControllerFailure(what);
    if (!failure_) {
      failure_ = what;
      if (threading_.on_failure) threading_.on_failure(what);
    }
    return false;
  }
  if (failure_log_.count()) {
    log_(
        fmt::format("controller: {}; the safety command was sent instead (t = {:g} s); {} failed steps so far "
                    "(logged: 1st, then every 100th)",
                    what, static_cast<double>(sim_now_ns) / 1e9, failure_log_.total()));
  }
  return true;
}

void ControllerNode::step_on_thread(std::int64_t now_ns, std::int64_t sim_now_ns, double dt_s) {
  auto job = std::make_shared<ControllerThread::Step>();
  job->observation = observation_;
  job->reference = reference_;
  job->dt_s = dt_s;
  job->output.outputs.assign(output_.outputs.size(), 0.0);
  const auto seconds = [](std::int64_t ns) { return fmt::format("{:g}", static_cast<double>(ns) / 1e9); };

  if (threading_.asynchronous) {
    {
      const std::lock_guard lock(publish_mutex_);
      if (failure_) return;  // the node has stopped answering
      step_in_flight_ = true;
    }
    const bool started = thread_->start(job, [this, sim_now_ns](ControllerThread::Step& s) {
      const std::lock_guard lock(publish_mutex_);
      step_in_flight_ = false;
      s.output.safety = false;
      if (s.error) {
        if (!controller_failed(s.error, sim_now_ns)) return;  // ends the node: nothing published
        s.output.safety = true;
        safety_output(s.reference, s.output);
      }
      output_ = s.output;
      publish(s.observation, s.reference, output_, sim_now_ns);
    });
    if (!started) {
      const std::lock_guard lock(publish_mutex_);
      step_in_flight_ = false;
      if (late_log_.count()) {
        log_("controller: tick of t = " + seconds(sim_now_ns) +
             " s not answered: the controller has not returned from its previous step; " +
             std::to_string(late_log_.total()) + " ticks not answered so far (logged: 1st, then every 100th)");
      }
      return;
    }
    last_step_ns_ = now_ns;
    return;
  }

  // Real time: wait for the controller up to the limit; the safety command when it is late.
  const bool returned = thread_->start(job) && thread_->wait_free(threading_.wait_ns);
  const std::lock_guard lock(publish_mutex_);
  if (!returned) {
    output_.safety = true;
    safety_output();
    if (late_log_.count()) {
      log_("controller: the controller did not return within " + seconds(threading_.wait_ns) +
           " s; the safety command was sent for the period of t = " + seconds(sim_now_ns) + " s; " +
           std::to_string(late_log_.total()) + " late periods so far (logged: 1st, then every 100th)");
    }
  } else if (job->error) {
    controller_failed(job->error, sim_now_ns);  // throws unless the safety command replaces the step
    output_.safety = true;
    safety_output();
  } else {
    output_ = job->output;
    output_.safety = false;
  }
  publish(observation_, reference_, output_, sim_now_ns);
  last_step_ns_ = now_ns;
}

void ControllerNode::republish() {
  const std::lock_guard lock(publish_mutex_);
  if (step_in_flight_) return;  // its continuation publishes the answer
  status_pub_.publish(status_);
  command_pub_.publish(command_msg_);
}

std::int64_t ControllerNode::newest_stamp_ns() const {
  const std::int64_t newest = std::max({pose_stamp_ns_, velocity_stamp_ns_, imu_stamp_ns_});
  return newest == kNever ? -1 : newest;
}

std::int64_t ControllerNode::synchronized_stamp_ns() const {
  if (pose_stamp_ns_ == kNever || pose_stamp_ns_ != velocity_stamp_ns_ || pose_stamp_ns_ != imu_stamp_ns_) {
    return -1;
  }
  return pose_stamp_ns_;
}

std::string ControllerNode::set_parameter(const std::string& name, const control::ParameterValue& value) {
  return control::set_parameter(settings_, *controller_, name, value);
}

std::optional<control::ParameterValue> ControllerNode::get_parameter(std::string_view name) const {
  return control::get_parameter(settings_, *controller_, name);
}

std::vector<const control::ParameterSpec*> ControllerNode::parameters() const {
  return control::all_parameters(*controller_);
}

}  // namespace quadcosim::sim
