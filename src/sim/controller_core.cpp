#include "sim/controller_core.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include "model/attitude.hpp"

namespace quadcosim::sim {

ControllerCore::ControllerCore(const control::ControllerConfig& config, const Topics& topics,
                               const sensors::SensorSet& carried)
    : controller_(config.controller ? config.controller->clone() : nullptr),
      settings_(config.node),
      trajectory_(config.trajectory),
      trajectory_offset_W_(config.trajectory_offset_W),
      hover_omega_rad_s_(config.vehicle.hover_omega_rad_s()),
      omega_min_rad_s_(config.vehicle.motor.omega_min_rad_s),
      log_([](const std::string& line) { std::cerr << line << '\n'; }),
      pose_topic_(topics.pose),
      velocity_topic_(topics.velocity),
      imu_topic_(topics.imu) {
  if (!controller_)
    throw std::invalid_argument("ControllerNode: the config has no controller (controllers::make_config)");
  output_.outputs.assign(controller_->output_names().size(), 0.0);
  sensors::for_each_configured(carried, [&]<class Kind>(const typename Kind::Config& c) {
    Extra& e = extras_[sensors::kind_index<Kind>()];
    e.divider = c.timing.divider;
    e.name = std::string(Kind::kName);
    observation_.sensors.carry<Kind>();
  });
}

bool ControllerCore::sensors_complete(std::int64_t stamp_ns, std::int64_t plant_period_ns) const {
  const std::int64_t tick = stamp_ns / plant_period_ns;
  for (const Extra& e : extras_) {
    if (e.divider > 0 && tick % e.divider == 0 && e.stamp_ns != stamp_ns) return false;
  }
  return true;
}

bool ControllerCore::accept_refused(const SensorCheck& check, const std::string& topic, int& backwards) {
  const bool stamp = check.fault == SensorFault::kStampBackwards || check.fault == SensorFault::kStampAhead;
  if (stamp && ++backwards > kStampRestartCount) {
    log_("controller: " + topic + ": " + std::to_string(kStampRestartCount) + " samples in a row " +
         (check.fault == SensorFault::kStampAhead ? "too far ahead of the newest accepted"
                                                  : "older than the newest accepted") +
         "; taking it that the sender's clock restarted (" + check.reason() + ")");
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

void ControllerCore::safety_output(const control::Reference& ref, control::ControllerOutput& out) const {
  // Algorithm 1, lines 3-5: every rotor at one speed; nothing else is decided. The attitude shown as
  // tracked is the reference's in attitude mode and level in position mode.
  out.omega_rad_s.setConstant(settings_.safety == control::SafetyMode::kHover ? hover_omega_rad_s_ : omega_min_rad_s_);
  out.level = control::CommandLevel::kRotorSpeeds;  // the safety speeds, whatever level the controller flies
  out.U.setZero();
  const bool attitude = ref.mode == control::Mode::kAttitude;
  out.roll_des_rad = attitude ? ref.roll_rad : 0.0;
  out.pitch_des_rad = attitude ? ref.pitch_rad : 0.0;
  out.yaw_des_rad = 0.0;
  out.attitude_error = std::numeric_limits<double>::quiet_NaN();
  out.rotor_saturated.reset(static_cast<int>(out.omega_rad_s.size()));
  out.tilt_saturated = false;
  std::fill(out.outputs.begin(), out.outputs.end(), std::numeric_limits<double>::quiet_NaN());
}

void ControllerCore::update_reference(std::int64_t now_ns) {
  if (trajectory_) {
    reference_ =
        control::trajectory_reference(trajectory_->at(static_cast<double>(now_ns) / 1e9), trajectory_offset_W_);
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

ControllerCore::Begun ControllerCore::begin_step(std::int64_t now_ns) {
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
  return {sim_now_ns, safety};
}

std::int64_t ControllerCore::newest_stamp_ns() const {
  const std::int64_t newest = std::max({pose_stamp_ns_, velocity_stamp_ns_, imu_stamp_ns_});
  return newest == kNever ? -1 : newest;
}

std::int64_t ControllerCore::synchronized_stamp_ns() const {
  if (pose_stamp_ns_ == kNever || pose_stamp_ns_ != velocity_stamp_ns_ || pose_stamp_ns_ != imu_stamp_ns_) {
    return -1;
  }
  return pose_stamp_ns_;
}

std::string ControllerCore::set_parameter(const std::string& name, const control::ParameterValue& value) {
  return control::set_parameter(settings_, *controller_, name, value);
}

std::optional<control::ParameterValue> ControllerCore::get_parameter(std::string_view name) const {
  return control::get_parameter(settings_, *controller_, name);
}

std::vector<const control::ParameterSpec*> ControllerCore::parameters() const {
  return control::all_parameters(*controller_);
}

}  // namespace quadcosim::sim
