// A flight controller (control::Controller, any registered type) as a node on the bus: its decisions
// are a sim::ControllerCore's (sim/controller_core.hpp: the latest Pose, Velocity and Imu, the
// reference, the stale-data safety of Algorithm 1, the controller's step), fed by the node's
// subscriptions; the node steps it on its period and publishes the rotor speeds on
// /<ns>/motor_commands and its status on /<ns>/controller_status. Parameters (the node's setpoints and
// safety, the controller's own table) change between steps. Sensor messages that fail the checks of
// sim/validation.hpp (NaN/Inf, non-unit quaternion, malformed or backward stamp) are dropped, counted
// in the status and logged (1st of each reason, then every 100th): the observation keeps its last valid
// values and ages, so the stale-data safety (Algorithm 1) takes over when nothing valid arrives.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "sim/controller_core.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {

class ControllerThread;

/// A controller's step failed (control/controller.hpp).
using ControllerFailure = control::ControllerFailure;

/// How a node runs its controller on a thread of its own (ControllerNode::run_controller_on_thread).
struct ControllerThreading {
  enum class OnError {
    kStop,    ///< a failed step ends the node (ControllerFailure)
    kSafety,  ///< a failed step sends the stale-data safety command; counted and logged
  };
  /// Lockstep: step() hands the controller its step and returns; the status and command are
  /// published from the controller's thread when it returns. A tick that comes while the controller
  /// is still busy is not answered (the plant's --timeout and --on-timeout apply).
  bool asynchronous = false;
  /// Real time: how long step() waits for the controller [ns]; when it has not returned by then, or
  /// is still busy with an earlier step, the safety command is sent for this period (counted).
  std::int64_t wait_ns = 0;
  OnError on_error = OnError::kStop;
  /// Asynchronous steps with kStop: called once, on the controller's thread, with the failure's
  /// message after the node stopped answering (the host ends; controller_failure() has it).
  std::function<void(const std::string&)> on_failure;
  /// What the controller's thread runs its loop in (ControllerThread::ThreadHost), when set.
  std::function<void(const std::function<void()>&)> thread_host;
};

class ControllerNode {
 public:
  /// Whether a sensor sample on a topic comes from the plant the node paired with (over DDS:
  /// dds/peer_pairing.hpp); one that does not is foreign: counted, logged rate-limited, not taken.
  using SampleFilter = std::function<bool(const std::string& topic, SenderId sender)>;

  /// Flies a clone of config.controller (which must be set). Without `accepts` every sample is the
  /// plant's (in-process: every message is the process's own). `carried`: the extra sensors the
  /// vehicle carries (the scenario's `sensors:`); the node subscribes their topics and the observation
  /// holds their samples (control::Observation::sensors).
  ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config,
                 SampleFilter accepts = {}, const sensors::SensorSet& carried = {});
  ~ControllerNode();

  /// From now on the controller runs on a thread of its own (sim/controller_thread.hpp): every call
  /// into it there, one at a time, so one that is slow or blocks holds up neither the transport's
  /// threads nor the parameter services. Call before the first step.
  void run_controller_on_thread(ControllerThreading threading);
  /// Steps whose controller failed (threw) and got the safety command instead (OnError::kSafety).
  std::uint64_t controller_failures() const { return failure_log_.total(); }
  /// Real time on a thread: periods whose controller had not returned in time (safety command sent);
  /// lockstep on a thread: ticks not answered because the controller was still busy.
  std::uint64_t late_steps() const { return late_log_.total(); }
  /// The failure that ended an asynchronous node (OnError::kStop), or nothing.
  std::optional<std::string> controller_failure() const;

  /// One control period ending now. `now_ns` is the node's current (simulated) time, `dt_s` its
  /// period; the age of the sensor data is measured against now_ns. Publishes the status, then the
  /// motor command.
  const control::ControllerOutput& step(std::int64_t now_ns, double dt_s);

  /// Real time: measure the age of sensor data by when it arrived on `clock` [ns] instead of by its
  /// stamp, so a plant that stops publishing is noticed even though its simulated time stops too.
  /// step() then takes now_ns on that clock.
  void use_receipt_clock(std::function<std::int64_t()> clock) { core_.use_receipt_clock(std::move(clock)); }

  /// The newest stamp [ns] among Pose, Velocity, Imu (simulated time), or -1 before any arrived.
  std::int64_t newest_stamp_ns() const { return core_.newest_stamp_ns(); }
  /// Sensor samples from writers other than the paired plant's, ignored (SampleFilter).
  std::uint64_t foreign_samples() const { return foreign_log_.total(); }

  /// Publishes the last status and command again (a lockstep peer that asked twice for one tick).
  void republish();

  /// Time [ns] of the last step, or INT64_MIN before the first.
  std::int64_t last_step_ns() const { return last_step_ns_; }

  /// Sets one parameter (the node's or the controller's); returns "" on success, else the reason it
  /// was refused (nothing changed).
  std::string set_parameter(const std::string& name, const control::ParameterValue& value) {
    return core_.set_parameter(name, value);
  }
  /// A parameter's value, or nothing for an unknown name.
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const {
    return core_.get_parameter(name);
  }
  /// Every parameter the node offers: its own, then its controller's.
  std::vector<const control::ParameterSpec*> parameters() const { return core_.parameters(); }

  const control::NodeSettings& settings() const { return core_.settings(); }
  const control::ControllerOutput& last_output() const { return core_.output(); }
  const control::Controller& controller() const { return core_.controller(); }
  /// The reference the last step followed.
  const control::Reference& reference() const { return core_.reference(); }
  /// The observation the last step used.
  const control::Observation& observation() const { return core_.observation(); }
  /// The stamp [ns] shared by the newest Pose, Velocity and Imu, when all three have arrived with the
  /// same stamp (a complete sample of one plant tick); -1 otherwise.
  std::int64_t synchronized_stamp_ns() const { return core_.synchronized_stamp_ns(); }
  /// What the node decides with (a scheduled parameter change is set here).
  ControllerCore& core() { return core_; }

  /// Called after each Pose, Velocity or Imu message (or a whole extra sensor sample) taken in, where the transport
  /// delivers it: a lockstep host steps from here (LockstepStepper) instead of polling after every wait.
  void on_sample(std::function<void()> f) { on_sample_ = std::move(f); }

  /// Where refused sensor messages are reported (rate-limited per reason). Default: stderr.
  void set_log(std::function<void(const std::string&)> log) { core_.set_log(std::move(log)); }

  /// The status published by the last step.
  const msg::ControllerStatus& status() const { return status_; }

 private:
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

  /// Publishes the status and command of a step at now_ns (simulated sim_now_ns) that used `obs`
  /// and `ref` and decided `out`.
  void publish(const control::Observation& obs, const control::Reference& ref, const control::ControllerOutput& out,
               std::int64_t sim_now_ns);
  /// The controller's step on its thread (run_controller_on_thread).
  void step_on_thread(std::int64_t now_ns, std::int64_t sim_now_ns, double dt_s);
  /// A failed step on the thread: the error policy. Returns true when the safety command replaces it.
  bool controller_failed(const std::exception_ptr& error, std::int64_t sim_now_ns);

  ControllerCore core_;
  std::int64_t last_step_ns_ = kNever;
  std::function<void()> on_sample_;
  msg::ControllerStatus status_;
  Publisher<msg::ControllerStatus> status_pub_;
  Publisher<msg::Float64MultiArray> command_pub_;
  msg::Float64MultiArray command_msg_;
  // The controller on its own thread (run_controller_on_thread): the core's controller is then its stand-in.
  ControllerThread* thread_ = nullptr;
  ControllerThreading threading_;
  /// Held while status_, command_msg_ and the core's output are written and published: an
  /// asynchronous step publishes from the controller's thread.
  mutable std::mutex publish_mutex_;
  bool step_in_flight_ = false;  ///< an asynchronous step has been started and not yet published
  std::optional<std::string> failure_;
  LogThrottle failure_log_, late_log_;
  SampleFilter accepts_;
  LogThrottle foreign_log_;  ///< foreign sensor samples: counted, logged 1st and every 100th
  /// A sample on `topic` from `sender` is the plant's; counts and logs it when not.
  bool from_plant(const std::string& topic, SenderId sender);
  /// Subscribes `topic`; each message, when from the plant, goes to take(m), and a true return to on_sample.
  template <class Message, class Take>
  void subscribe_sample(Transport& transport, const std::string& topic, Take take);
  /// Subscribes the extra sensors' topics (sim/sensor_wire.hpp), a sample taken when all its messages of
  /// one stamp have come.
  void subscribe_sensors(Transport& transport, const std::string& ns, const sensors::SensorSet& carried);
};

}  // namespace quadcosim::sim
