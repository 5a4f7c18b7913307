#include "sim/controller_node.hpp"

#include <algorithm>
#include <iostream>

#include "model/attitude.hpp"

namespace quadcosim::sim {

ControllerNode::ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config)
    : config_(config), controller_(config.params) {
  log_ = [](const std::string& line) { std::cerr << line << '\n'; };
  status_pub_ = transport.advertise<msg::ControllerStatus>(topics.controller_status);
  command_pub_ = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  command_msg_.data.resize(4);
  command_msg_.dim = {{"", 4, 4}};
  transport.subscribe<msg::PoseStamped>(topics.pose, [this, topic = topics.pose](const msg::PoseStamped& m) {
    if (!accept(check_pose(m, pose_stamp_ns_), topic, pose_backwards_)) return;
    observation_.p_W = {m.position.x, m.position.y, m.position.z};
    pose_stamp_ns_ = m.header.stamp.to_ns();
    pose_ref_ns_ = reference(pose_stamp_ns_);
    if (on_sample_) on_sample_();
  });
  transport.subscribe<msg::TwistStamped>(topics.velocity, [this, topic = topics.velocity](const msg::TwistStamped& m) {
    if (!accept(check_velocity(m, velocity_stamp_ns_), topic, velocity_backwards_)) return;
    observation_.v_W = {m.linear.x, m.linear.y, m.linear.z};
    velocity_stamp_ns_ = m.header.stamp.to_ns();
    velocity_ref_ns_ = reference(velocity_stamp_ns_);
    if (on_sample_) on_sample_();
  });
  transport.subscribe<msg::Imu>(topics.imu, [this, topic = topics.imu](const msg::Imu& m) {
    if (!accept(check_imu(m, imu_stamp_ns_), topic, imu_backwards_)) return;
    // Kept as received; turned into Euler angles when a step uses it (the plant publishes at twice
    // the control rate, so converting on arrival would do half the atan2s for nothing).
    imu_q_WB_ = Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z);
    imu_pending_ = true;
    observation_.w_B = {m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z};
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

const control::ControllerOutput& ControllerNode::step(std::int64_t now_ns, double dt_s) {
  if (imu_pending_) {
    const model::Euler e = model::euler_from_quaternion(imu_q_WB_);
    observation_.roll_rad = e.roll_rad;
    observation_.pitch_rad = e.pitch_rad;
    observation_.yaw_rad = e.yaw_rad;
    imu_pending_ = false;
  }
  const std::int64_t oldest = std::min({pose_ref_ns_, velocity_ref_ns_, imu_ref_ns_});
  observation_.age_s =
      oldest == kNever ? std::numeric_limits<double>::infinity() : static_cast<double>(now_ns - oldest) / 1e9;
  output_ = controller_.step(observation_, config_.setpoint, dt_s);

  const auto& sp = config_.setpoint;
  const bool position = sp.mode == control::Mode::kPosition;
  // The status is stamped with simulated time: the step's time, or the newest sample's in real time.
  const std::int64_t sim_now_ns = receipt_clock_ ? std::max<std::int64_t>(newest_stamp_ns(), 0) : now_ns;
  status_.header.stamp = msg::Time::from_ns(sim_now_ns);
  if (const char* mode = control::to_string(sp.mode); status_.mode != mode) status_.mode = mode;
  status_.setpoint = {sp.p_des_W.x(),
                      sp.p_des_W.y(),
                      sp.p_des_W.z(),
                      position ? output_.roll_des_rad : sp.roll_des_rad,
                      position ? output_.pitch_des_rad : sp.pitch_des_rad,
                      sp.yaw_des_rad};
  for (int i = 0; i < 4; ++i) {
    status_.u[i] = output_.U[i];
    status_.error[i] = output_.error[i];
    status_.rotor_saturated[i] = output_.rotor_saturated[i];
  }
  status_.tilt_saturated = output_.tilt_saturated;
  status_.safety = output_.safety;
  status_.rejected_non_finite = fault_log_[static_cast<int>(SensorFault::kNonFinite)].total();
  status_.rejected_bad_quaternion = fault_log_[static_cast<int>(SensorFault::kBadQuaternion)].total();
  status_.rejected_bad_stamp = fault_log_[static_cast<int>(SensorFault::kBadStamp)].total();
  status_.rejected_stamp_backwards = fault_log_[static_cast<int>(SensorFault::kStampBackwards)].total();
  status_pub_.publish(status_);

  for (int i = 0; i < 4; ++i) command_msg_.data[i] = output_.omega_rad_s[i];
  msg::write_command_label(command_msg_.dim[0].label, sim_now_ns);
  command_pub_.publish(command_msg_);
  last_step_ns_ = now_ns;
  return output_;
}

void ControllerNode::republish() {
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
  control::ControllerConfig next = config_;
  if (std::string err = control::set_parameter(next, name, value); !err.empty()) return err;
  if (control::find_parameter(name)->affects_design) {
    try {
      controller_.set_params(next.params);
    } catch (const std::exception& e) {
      return name + ": " + e.what();
    }
  }
  config_ = next;
  return {};
}

}  // namespace quadcosim::sim
