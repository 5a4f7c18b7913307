// The plant as a node: integrates the model on integer ticks, publishes the paper's sensor topics and
// /clock, and takes rotor speed commands from /<ns>/motor_commands (zero-order hold), or a command at
// any level: named in that topic's layout ("level=ctbr") or typed on /<ns>/cmd/<level>
// (sim/level_messages.hpp). All go through one intake; one topic commands a tick.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "sim/clock.hpp"
#include "sim/external_dynamics.hpp"
#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "sim/plant_core.hpp"
#include "sim/realism.hpp"
#include "sim/sensor_channels.hpp"
#include "sim/steppable_plant.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {

struct PlantOptions {
  TickClock clock;
  int substeps = 1;             ///< RK4 steps per plant tick
  int command_delay_ticks = 0;  ///< a command received during tick k takes effect at tick k + delay
  std::string frame_id = "world";
  /// Lockstep: a command labelled with a stamp older than the current tick answers an earlier tick,
  /// and a second command with the label already received is a copy of it (the controller answers
  /// a repeated tick again): both are repeats, dropped and counted in commands_stale.
  /// Commands' labels are read only with this set (msg::command_stamp_ns).
  bool drop_stale_commands = false;
  /// Watchdog limit [ticks]: when no valid command has been received for this long, the policy
  /// acts until one arrives. 0 switches the watchdog off. Measured in simulated ticks, or on the
  /// receipt clock after use_receipt_clock().
  Tick watchdog_ticks = 50;
  WatchdogPolicy watchdog_policy = WatchdogPolicy::kStop;
  /// The gains of the inner loops that fly commands above rotor speeds (the scenario's `inner_loops:`);
  /// none: control::InnerLoopParams::for_vehicle. Checked for the vehicle and period when the node is made.
  std::optional<control::InnerLoopParams> inner_loops;
  /// Sensor noise, rates and latency, wind, rotor faults (sim/realism.hpp); all off by default.
  RealismConfig realism;
  /// /<ns>/plant_status goes out on every tick whose counters changed and at least every this many
  /// ticks; 0: once per simulated second.
  Tick status_period_ticks = 0;
  /// Publish /clock. It is global, not namespaced: when one process hosts many plants, one of them
  /// publishes it.
  bool publish_clock = true;
  /// Publish /clock after Pose, Velocity and Imu of the tick instead of before them. For a peer that
  /// steps when /clock reaches its next sample hit and then reads the newest sample of each topic (a
  /// Simulink node with ROS 2 time model stepping, docs/simulink.md): delivered in publication order,
  /// the tick's samples are in before the time that steps it.
  bool clock_after_sensors = false;
  /// The vehicle for 3D views: /tf (frame_id -> <ns>/base_link, the true pose, every tick), and once,
  /// at the first tick, /tf_static (base_link -> rotors) and <ns>/robot_description (a URDF of the
  /// vehicle); sim/vehicle_description.hpp. Off: none of the three.
  bool publish_tf = true;
  /// Dynamics computed elsewhere (an FMU, sim/external_dynamics.hpp), one instance made per plant;
  /// null: the native 6-DOF model. Commands, delay, watchdog, status, topics and the sensor realism
  /// (noise, rates, latency) are the node's either way; wind, rotor faults and aerodynamic drag act
  /// inside the native model only (external_plant_conflict refuses them).
  std::shared_ptr<const ExternalDynamicsFactory> external;
  /// Subscribe the typed command topics /<ns>/cmd/<level> beside motor_commands. Off for a host whose
  /// controllers are quadcosim's own (a DDS swarm: seven readers fewer per vehicle to discover).
  bool typed_command_topics = true;
};

/// "" when the native-only features (wind, rotor faults, the vehicle's aerodynamics) are all off,
/// else the scenario key of the first one that is on ("environment", "faults",
/// "vehicle.aero.linear_drag_N_s_m.x"): a plant with PlantOptions::external cannot honour it.
std::string external_plant_conflict(const RealismConfig& realism, const model::VehicleParams& vehicle);

/// What became of the motor commands (sim/validation.hpp check_command).
struct PlantStats {
  std::uint64_t commands_received = 0;
  std::uint64_t commands_accepted = 0;             ///< used, clamped ones included (not repeats)
  std::uint64_t commands_rejected = 0;             ///< wrong length or non-finite: ignored, last good one held
  std::uint64_t commands_rejected_length = 0;      ///< of those: not exactly 4 values
  std::uint64_t commands_rejected_non_finite = 0;  ///< of those: a NaN/Inf speed
  std::uint64_t commands_clamped = 0;              ///< a speed < 0 or > omega_max: used clamped to [0, omega_max]
  std::uint64_t commands_stale =
      0;  ///< lockstep repeats (an earlier tick's command, or a second copy of this one), dropped
  /// From a writer other than the paired controller's (set_command_filter): ignored, in no other count
  std::uint64_t commands_foreign = 0;
  /// On a second command topic for a tick another already commanded (the same plant tick, or in lockstep
  /// the same label): ignored, in no other count (not received, no answer)
  std::uint64_t commands_rejected_second_topic = 0;
  /// A ThrustAttitude whose attitude is not a unit quaternion: also in commands_rejected
  std::uint64_t commands_rejected_bad_quaternion = 0;
  /// The controller's, arriving while before_clock held a tick's /clock back: not a timer's answer on
  /// ROS time (it came before the time that fires the timer). Ignored, in no other count; reported to
  /// the early-command callback.
  std::uint64_t commands_early = 0;
  std::uint64_t watchdog_trips = 0;  ///< times the watchdog took over (no valid command for its limit)
  std::uint64_t watchdog_ticks = 0;  ///< ticks latched under the watchdog's policy
  std::string last_problem;          ///< the reason given for the newest rejected/clamped command
};

/// The native plant behind the steppable-plant seam (sim/steppable_plant.hpp).
class PlantNode final : public SteppablePlant {
 public:
  /// With options.external, makes its ExternalDynamics (what the factory throws goes through) and
  /// throws std::invalid_argument naming the key when external_plant_conflict finds one.
  PlantNode(Transport& transport, const Topics& topics, const model::VehicleParams& vehicle,
            const PlantOptions& options, const model::State& initial);

  /// Where rejected and clamped commands are reported (rate-limited: the first of each kind, then
  /// every 100th, each line with the count so far). Default: stderr.
  void set_log(std::function<void(const std::string&)> log) { log_ = std::move(log); }

  /// Commands whose sender `accepts` (with the command's topic: motor_commands or a /<ns>/cmd/<level>)
  /// refuses are foreign: counted (commands_foreign), logged rate-limited, and otherwise ignored (not
  /// received, not an answer, no label seen). Unset: every sender is the controller (in-process, where
  /// every message is the process's own).
  void set_command_filter(std::function<bool(const std::string&, SenderId)> accepts) {
    command_filter_ = std::move(accepts);
  }

  /// With clock_after_sensors: runs after tick k's Pose, Velocity and Imu went out, before its /clock
  /// (a lockstep plant over DDS waits there at tick 0 until the peer has the samples). Returning false
  /// holds tick k's /clock back: the caller publishes it later with publish_clock(k).
  void before_clock(std::function<bool(Tick)> f) { before_clock_ = std::move(f); }
  /// Publishes /clock for tick k (one that before_clock held back).
  void publish_clock(Tick k);
  /// Told of each command of the controller's that arrives while a tick's /clock is held back
  /// (commands_early), with that tick: the lockstep host decides what it means.
  void on_early_command(std::function<void(Tick)> f) { on_early_command_ = std::move(f); }
  /// Told of each command of the controller's labelled with a stamp older than the current tick k
  /// (dropped and counted in commands_stale as a repeat), with that label and k: where the controller
  /// cannot answer a tick twice (a timer on ROS time), it is no repeat but a step on older samples,
  /// and the lockstep host decides what that means.
  void on_label_behind(std::function<void(std::int64_t, Tick)> f) { on_label_behind_ = std::move(f); }
  /// Changes PlantOptions::clock_after_sensors before the first tick (a lockstep plant decides once it
  /// knows how its controller steps).
  void set_clock_after_sensors(bool after) { options_.clock_after_sensors = after; }

  /// Publishes /clock, Pose, Velocity and Imu for the state at tick k (/clock last with
  /// clock_after_sensors), and the plant status when due.
  void publish_outputs(Tick k) override;
  /// Fixes the command that acts over [t_k, t_k+1): the newest one whose delay has elapsed.
  void latch_command(Tick k) override;
  /// Real time: measure the watchdog on `clock` [ns] (when commands arrive) instead of in ticks, so a
  /// controller that stops is noticed whatever the plant's simulated time does.
  void use_receipt_clock(std::function<std::int64_t()> clock) { receipt_clock_ = std::move(clock); }
  /// True while the watchdog's policy sets the latched command (since the last latch_command).
  bool watchdog_active() const { return watchdog_active_; }
  /// Time [ns] without a valid command at the last latch_command (ticks * period, or receipt clock).
  std::int64_t command_age_ns() const { return command_age_ns_; }
  /// Integrates the state from t_k to t_k+1 under the latched command (external dynamics: steps them).
  void integrate(Tick k) override;

  /// The state at the current tick (external dynamics: as they reported it at the last
  /// publish_outputs).
  const model::State& state() const { return core_.state(); }
  const model::Quadrotor& model() const { return core_.model(); }
  /// The command latched for the current interval, as received after check_command (speeds within
  /// [0, omega_max]; the model still limits them to [omega_min, omega_max]).
  const model::RotorVector& latched_command() const { return core_.latched(); }
  /// The plant core (the level command held, the inner loops flying it).
  const PlantCore& core() const { return core_; }
  const PlantStats& stats() const { return stats_; }
  /// The controller's commands (foreign and stale ones aside); its label_ns is the stamp label of the
  /// newest of them, accepted or rejected (a rejected command answers its tick: the last good one is
  /// held, as in-process). Labels are read with drop_stale_commands (lockstep) only, otherwise it
  /// stays -1.
  CommandReceipt command_receipt() const override {
    return {stats_.commands_received - stats_.commands_stale, last_command_stamp_ns_};
  }
  const PlantOptions& options() const { return options_; }
  Tick current_tick() const { return current_tick_; }
  /// The extra sensors' newest samples (sensors/suite.hpp); null when the scenario configures none.
  const sensors::Suite* extra_sensors() const { return core_.extra_sensors(); }

 private:
  void on_command(const msg::Float64MultiArray& m, SenderId sender);
  /// A typed command (/<ns>/cmd/<level>).
  template <class T>
  void on_level_command(const T& m, SenderId sender);
  /// The one intake of every command, whatever its topic (`source`: 0 motor_commands, 1 + level for
  /// /<ns>/cmd/<level>): the sender filter, a held /clock, the one-topic-per-tick rule, lockstep
  /// repeats by `stamp` (the label; -1: none), then `check()`'s verdict counted, the command queued.
  template <class Check>
  void intake(int source, SenderId sender, std::int64_t stamp, Check check);
  void publish_status(Tick k);
  /// The external dynamics' outputs at tick k; the core's state becomes the state they report.
  model::Outputs external_outputs(Tick k);

  PlantCore core_;  ///< the model, its state, the command queue and latch, the realism
  PlantOptions options_;
  std::unique_ptr<ExternalDynamics> external_;  ///< options.external's dynamics; null: the core's model
  Tick current_tick_ = 0;
  std::int64_t last_command_stamp_ns_ = -1;
  std::int64_t last_label_accepted_ns_ = -1;  ///< label of the newest accepted command (a copy is a repeat)
  PlantStats stats_;
  std::function<std::int64_t()> receipt_clock_;
  std::int64_t last_valid_receipt_ns_ = -1;  ///< receipt clock: its arrival (-1: none, from the first latch)
  std::int64_t command_age_ns_ = 0;
  bool watchdog_active_ = false;
  std::function<void(const std::string&)> log_;
  LogThrottle rejected_log_, clamped_log_, foreign_log_;
  std::function<bool(const std::string&, SenderId)> command_filter_;
  /// The command topics: [0] motor_commands, [1 + level] /<ns>/cmd/<level>.
  std::array<std::string, 1 + control::kCommandLevelCount> command_topics_;
  int last_source_ = -1;                 ///< the topic of the newest command that answered a tick
  Tick last_source_tick_ = -1;           ///< the tick it arrived in
  std::int64_t last_source_label_ = -1;  ///< its label (lockstep), -1 for none
  LogThrottle second_topic_log_;
  msg::PlantStatus status_;
  Tick status_period_ticks_ = 1;  ///< ticks between periodic statuses (options or one simulated second)
  msg::PoseStamped pose_;         ///< the outgoing sensor messages, reused from tick to tick
  msg::TwistStamped twist_;
  msg::Imu imu_;
  Tick last_status_tick_ = -1;
  Publisher<msg::PlantStatus> status_pub_;
  Publisher<msg::Clock> clock_pub_;
  std::function<bool(Tick)> before_clock_;
  std::function<void(Tick)> on_early_command_;
  std::function<void(std::int64_t, Tick)> on_label_behind_;
  Tick clock_held_ = -1;  ///< the tick whose /clock before_clock held back, until publish_clock
  Publisher<msg::PoseStamped> pose_pub_;
  Publisher<msg::TwistStamped> velocity_pub_;
  Publisher<msg::Imu> imu_pub_;
  /// The magnetometer, barometer, GNSS the scenario configures (options.realism.extra_sensors); null
  /// when it configures none.
  std::unique_ptr<SensorChannels> extra_sensors_;
  msg::TFMessage tf_;  ///< one transform, frame ids set once
  Publisher<msg::TFMessage> tf_pub_;
  // Published at the first publish_outputs (built in the constructor: no allocation on a tick).
  msg::TFMessage tf_static_;
  msg::String description_;
  bool description_sent_ = false;
  Publisher<msg::TFMessage> tf_static_pub_;
  Publisher<msg::String> description_pub_;
};

}  // namespace quadcosim::sim
