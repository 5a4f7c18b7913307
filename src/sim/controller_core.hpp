// What a controller node decides, without the bus: the latest Pose, Velocity and Imu taken in (checked
// by sim/validation.hpp; the IMU quaternion turned into Z-Y-X Euler angles when a step uses it, as the
// paper's imuCallback does), the reference (the step setpoints, or the scenario's trajectory), the
// stale-data safety of Algorithm 1 (an observation older than stale_limit or not finite: the safety
// speeds, the controller not stepped) and the controller's step. The node parameters and the
// controller's own table change between steps.
//
// sim::ControllerNode wraps one in the bus (subscriptions, the published status and command, a
// controller on a thread of its own); quadcosim.Batch steps one per vehicle directly, fed by the
// vehicle's plant (src/python/batch.cpp): the same calls in the same order, so the same numbers.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "sensors/registry.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {

/// The motor command message of a step's output: its rotor speeds, or the setpoint of the level it
/// commands, named in the layout (msg::set_command_level). `m.dim[0]` (the lockstep label) is kept.
inline void write_command(const control::ControllerOutput& out, msg::Float64MultiArray& m) {
  const bool speeds = out.level == control::CommandLevel::kRotorSpeeds;
  const auto n = static_cast<std::size_t>(speeds ? out.omega_rad_s.size() : 4);  // one per rotor, or 4
  const double* v = speeds ? out.omega_rad_s.data() : out.setpoint.data();
  if (n == 4) {
    m.data.resize(4);
    for (std::size_t i = 0; i < 4; ++i) m.data[i] = v[i];
  } else {
    m.data.assign(v, v + n);
  }
  // Rotor speeds carry no level dimension (the message as before levels existed): set_command_level
  // removes one left from an earlier step.
  msg::set_command_level(m, control::to_string(out.level));
}

class ControllerCore {
 public:
  /// Flies a clone of config.controller (which must be set: std::invalid_argument otherwise). The
  /// topics name the sensor topics in the log of refused samples. `carried`: the extra sensors the
  /// vehicle carries (the scenario's `sensors:`), whose samples the observation holds (take()).
  ControllerCore(const control::ControllerConfig& config, const Topics& topics, const sensors::SensorSet& carried = {});

  /// Sensor samples: true when taken; a sample that fails its check is counted, logged (1st of each
  /// reason, then every 100th) and dropped, the observation keeping its last valid values and ages.
  bool take_pose(const msg::PoseStamped& m) {
    const std::int64_t received = receipt_now();
    const SensorCheck check = check_pose(m, pose_stamp_ns_, ahead_limit(pose_ref_ns_, received));
    if (!accept(check, pose_topic_, pose_backwards_)) return false;
    observation_.p_W = {m.position.x, m.position.y, m.position.z};
    pose_stamp_ns_ = m.header.stamp.to_ns();
    pose_ref_ns_ = reference_time(pose_stamp_ns_, received);
    return true;
  }
  bool take_velocity(const msg::TwistStamped& m) {
    const std::int64_t received = receipt_now();
    const SensorCheck check = check_velocity(m, velocity_stamp_ns_, ahead_limit(velocity_ref_ns_, received));
    if (!accept(check, velocity_topic_, velocity_backwards_)) return false;
    observation_.v_W = {m.linear.x, m.linear.y, m.linear.z};
    velocity_stamp_ns_ = m.header.stamp.to_ns();
    velocity_ref_ns_ = reference_time(velocity_stamp_ns_, received);
    return true;
  }
  bool take_imu(const msg::Imu& m) {
    const std::int64_t received = receipt_now();
    const SensorCheck check = check_imu(m, imu_stamp_ns_, ahead_limit(imu_ref_ns_, received));
    if (!accept(check, imu_topic_, imu_backwards_)) return false;
    // Kept as received; turned into Euler angles when a step uses it (the plant publishes at twice
    // the control rate, so converting on arrival would do half the atan2s for nothing).
    observation_.q_WB = Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z);
    imu_pending_ = true;
    observation_.w_B = {m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z};
    observation_.specific_force_B = {m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z};
    imu_stamp_ns_ = m.header.stamp.to_ns();
    imu_ref_ns_ = reference_time(imu_stamp_ns_, received);
    return true;
  }

  /// An extra sensor's sample (Kind carried), as read from its message(s) (sim/sensor_wire.hpp),
  /// stamped `stamp`: checked as the others (sim::check_sample), then the observation's reading.
  template <class Kind>
  bool take(const typename Kind::Sample& sample, const msg::Time& stamp) {
    Extra& e = extras_[sensors::kind_index<Kind>()];
    const std::int64_t received = receipt_now();
    const SensorCheck check = check_sample<Kind>(sample, stamp, e.stamp_ns, ahead_limit(e.ref_ns, received));
    if (!accept(check, e.name, e.backwards)) return false;
    e.stamp_ns = stamp.to_ns();
    e.ref_ns = reference_time(e.stamp_ns, received);
    observation_.sensors.set<Kind>(sample, e.stamp_ns);
    return true;
  }
  /// Whether every carried extra sensor that publishes at plant tick stamp_ns / plant_period_ns (its
  /// divider) has its sample of that stamp: with Pose, Velocity and Imu of it, the tick is complete.
  bool sensors_complete(std::int64_t stamp_ns, std::int64_t plant_period_ns) const;

  /// A step at now_ns [ns, the node's clock] begins: the observation completed (Euler angles, age,
  /// stamps) and the reference evaluated at the step's simulated time.
  struct Begun {
    std::int64_t sim_now_ns;  ///< now_ns, or the newest sample's stamp on the receipt clock
    bool safety;              ///< Algorithm 1, lines 3-5: the observation is stale or not finite
  };
  Begun begin_step(std::int64_t now_ns);
  /// The begun step's decision into output(): the safety command, or the controller's step over dt_s.
  void decide(bool safety, double dt_s) {
    output_.safety = safety;
    if (safety) {
      safety_output(reference_, output_);
    } else {
      controller_->step(observation_, reference_, dt_s, output_);
    }
  }
  /// The stale-data safety command for `ref` into `out` (every rotor at one speed; nothing else decided).
  void safety_output(const control::Reference& ref, control::ControllerOutput& out) const;

  /// Real time: measure the age of sensor data by when it arrived on `clock` [ns] instead of by its
  /// stamp, so a plant that stops publishing is noticed even though its simulated time stops too.
  void use_receipt_clock(std::function<std::int64_t()> clock) { receipt_clock_ = std::move(clock); }
  bool on_receipt_clock() const { return static_cast<bool>(receipt_clock_); }

  /// The newest stamp [ns] among Pose, Velocity, Imu (simulated time), or -1 before any arrived.
  std::int64_t newest_stamp_ns() const;
  /// The stamp [ns] shared by the newest Pose, Velocity and Imu when all three have the same one, else -1.
  std::int64_t synchronized_stamp_ns() const;

  /// Sets one parameter (the node's or the controller's); "" on success, else the reason (nothing changed).
  std::string set_parameter(const std::string& name, const control::ParameterValue& value);
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const;
  std::vector<const control::ParameterSpec*> parameters() const;

  const control::NodeSettings& settings() const { return settings_; }
  const control::Controller& controller() const { return *controller_; }
  /// Where the controller lives (a node moves it onto a thread of its own and puts a stand-in here).
  std::unique_ptr<control::Controller>& controller_slot() { return controller_; }
  const control::Observation& observation() const { return observation_; }
  const control::Reference& reference() const { return reference_; }
  const control::ControllerOutput& output() const { return output_; }
  control::ControllerOutput& output() { return output_; }
  /// Sensor samples refused for `fault` so far.
  std::uint64_t rejected(SensorFault fault) const { return fault_log_[static_cast<int>(fault)].total(); }

  /// Where refused samples are reported (and whatever a host logs through log()). Default: stderr.
  void set_log(std::function<void(const std::string&)> log) { log_ = std::move(log); }
  void log(const std::string& line) const { log_(line); }

 private:
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

  /// True when a sample is to be used: its check passed, or else (accept_refused) it is the sample
  /// after a sender's clock restart (kStampRestartCount well-formed samples in a row refused as older
  /// than the newest); a refusal is counted and logged.
  bool accept(const SensorCheck& check, const std::string& topic, int& backwards) {
    if (check.ok()) {
      backwards = 0;
      return true;
    }
    return accept_refused(check, topic, backwards);
  }
  bool accept_refused(const SensorCheck& check, const std::string& topic, int& backwards);
  /// The receipt clock's time now (read once per sample), or kNever without one.
  std::int64_t receipt_now() const { return receipt_clock_ ? receipt_clock_() : kNever; }
  /// What a sample's age is measured from: its receipt time on the receipt clock, else its stamp.
  std::int64_t reference_time(std::int64_t stamp_ns, std::int64_t received_ns) const {
    return receipt_clock_ ? received_ns : stamp_ns;
  }
  /// How far ahead of the newest accepted stamp a topic's next may be: kStampAheadLimitNs, plus on the
  /// receipt clock the time since that newest was taken (`ref_ns`, its receipt time, until
  /// `received_ns`): a plant whose samples were cut off for longer has simulated on meanwhile, in
  /// real time.
  std::int64_t ahead_limit(std::int64_t ref_ns, std::int64_t received_ns) const {
    return receipt_clock_ && ref_ns != kNever ? kStampAheadLimitNs + std::max<std::int64_t>(received_ns - ref_ns, 0)
                                              : kStampAheadLimitNs;
  }
  /// reference_ at simulated time now_ns: the step setpoints (or the trajectory).
  void update_reference(std::int64_t now_ns);

  // What a tick and a step read, first.
  std::unique_ptr<control::Controller> controller_;
  control::Observation observation_;
  control::Reference reference_;
  control::ControllerOutput output_;
  /// Header stamps of the newest samples, and the times their age is measured from (the stamps, or
  /// the receipt times under use_receipt_clock).
  std::int64_t pose_stamp_ns_ = kNever, velocity_stamp_ns_ = kNever, imu_stamp_ns_ = kNever;
  std::int64_t pose_ref_ns_ = kNever, velocity_ref_ns_ = kNever, imu_ref_ns_ = kNever;
  int pose_backwards_ = 0, velocity_backwards_ = 0, imu_backwards_ = 0;
  bool imu_pending_ = false;  ///< observation_.q_WB not yet turned into its Euler angles
  control::NodeSettings settings_;
  std::shared_ptr<const trajectory::Trajectory> trajectory_;
  Eigen::Vector3d trajectory_offset_W_;
  double hover_omega_rad_s_, omega_min_rad_s_;  ///< the safety speeds of SafetyMode kHover and kStop
  std::function<std::int64_t()> receipt_clock_;
  std::array<LogThrottle, kSensorFaultCount> fault_log_;  ///< per SensorFault: counts and log pacing
  std::function<void(const std::string&)> log_;
  std::string pose_topic_, velocity_topic_, imu_topic_;  ///< for the log of refused samples
  /// Per kind of sensors::Kinds: the extra sensor's newest accepted stamp and its reference time (as
  /// for Pose), the backwards count, its divider (0: not carried) and its name for the log.
  struct Extra {
    std::int64_t stamp_ns = kNever, ref_ns = kNever;
    int backwards = 0;
    int divider = 0;
    std::string name;
  };
  std::array<Extra, std::tuple_size_v<sensors::Kinds>> extras_;
};

}  // namespace quadcosim::sim
