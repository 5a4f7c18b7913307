// The native plant's tick without a bus: the 6-DOF model's state, the outputs of a tick and the
// sensor messages made of them (with the sensor realism: noise, rates, latency), the vehicle's extra
// sensors (magnetometer, barometer, GNSS: its sensors::Suite, SI samples), the command intake (a
// command message checked, then queued to take effect command_delay_ticks after the tick it arrived
// in), the zero-order hold of the newest due command and the watchdog's decision on the command's
// age, and the integration to the next tick (wind, rotor faults and drag acting inside the model).
//
// A tick is these phases, in the order sim::SteppablePlant states (steppable_plant.hpp): outputs and
// sense (+ sense_extra), the commands that arrive (take_command), latch, integrate. sim::PlantNode
// puts them on a bus (topics, who may command, lockstep labels, statistics and logs, a receipt clock
// in real time, external dynamics); quadcosim.Batch calls them per vehicle directly
// (src/python/batch.cpp); the plant FMU (src/fmi/export/plant_model.cpp) takes its rotor speeds as an
// FMI input acting over the step (set_latched: no queue, no watchdog). The options are the caller's
// (a node keeps its own copy; a batch's vehicles share their scenario's).
//
// A command may be at a level above rotor speeds (control/command_level.hpp: ctbr, velocity, ...): it
// is checked and queued the same way, and once latched it is held, and the inner loops
// (control/inner_loops.hpp) turn it into the rotor speeds of every tick from the true state at that
// tick, until a newer command or the watchdog's stop replaces it.
#pragma once

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/command_level.hpp"
#include "control/inner_loops.hpp"
#include "model/quadrotor.hpp"
#include "sensors/suite.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"
#include "sim/realism.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {

/// What the plant does with its motors when no valid command has arrived for the watchdog limit.
enum class WatchdogPolicy {
  kHold,  ///< keep the last valid command
  kStop,  ///< all motors to the vehicle's omega_min_rad_s (0 by default: the motors stop)
};
inline std::string to_string(WatchdogPolicy p) { return p == WatchdogPolicy::kHold ? "hold" : "stop"; }

/// The sensor messages of the plant's outputs `y` at `stamp` as the plant publishes them: every field
/// a tick changes (the frame ids are set once). With sensor realism, PlantRealism::measure then
/// overwrites what the sensors measure.
inline void write_sensor_messages(const model::Outputs& y, const msg::Time& stamp, msg::PoseStamped& pose,
                                  msg::TwistStamped& twist, msg::Imu& imu) {
  const auto v3 = [](const Eigen::Vector3d& v) { return msg::Vector3{v.x(), v.y(), v.z()}; };
  const auto q = msg::Quaternion{y.q_WB.x(), y.q_WB.y(), y.q_WB.z(), y.q_WB.w()};
  pose.header.stamp = stamp;
  pose.position = v3(y.p_W);
  pose.orientation = q;
  twist.header.stamp = stamp;
  twist.linear = v3(y.v_W);
  twist.angular = v3(y.w_B);
  imu.header.stamp = stamp;
  imu.orientation = q;
  imu.angular_velocity = v3(y.w_B);
  imu.linear_acceleration = v3(y.specific_force_B);
}

class PlantCore {
 public:
  PlantCore() = default;
  /// The realism (noise streams named by `ns`, the vehicle's namespace "/drone") is made when
  /// `realism` is active or the vehicle has aerodynamic drag; the paper's plant otherwise. The extra
  /// sensors are realism.extra_sensors (none: no suite), seeded by realism.seed. `environment`: make
  /// the realism even when nothing of `realism` is active (a host that switches parts of a configured
  /// realism off, the plant FMU, keeps the model's path through an Environment, whatever it holds).
  PlantCore(const model::VehicleParams& vehicle, const RealismConfig& realism, const TickClock& clock,
            const model::State& initial, const std::string& ns, bool environment = false)
      : model_(vehicle),
        state_(initial),
        latched_(initial.omega_rad_s),
        rotor_input_(model_->rotor_input(latched_)),
        period_s_(clock.period_s()) {
    if (environment || realism.active() || vehicle.aero.active()) {
      realism_ = std::make_unique<PlantRealism>(realism, vehicle, ns, clock);
    }
    if (realism.extra_sensors.any()) {
      extra_ = std::make_unique<sensors::Suite>(realism.extra_sensors, realism.seed, ns, clock.period_ns);
    }
    pending_.reserve(4);  // now, beside the rest of the plant, not at the first command
  }
  /// A copy steps on from the same state, the same draws to come (the plant FMU's saved states).
  PlantCore(const PlantCore& o)
      : model_(o.model_),
        state_(o.state_),
        latched_(o.latched_),
        rotor_input_(o.rotor_input_),
        last_valid_tick_(o.last_valid_tick_),
        period_s_(o.period_s_),
        held_(o.held_),
        inner_(o.inner_ ? std::make_unique<Inner>(*o.inner_) : nullptr),
        pending_(o.pending_),
        pending_head_(o.pending_head_),
        realism_(o.realism_ ? std::make_unique<PlantRealism>(*o.realism_) : nullptr),
        extra_(o.extra_ ? std::make_unique<sensors::Suite>(*o.extra_) : nullptr) {}
  PlantCore& operator=(const PlantCore& o) {
    if (this != &o) *this = PlantCore(o);
    return *this;
  }
  PlantCore(PlantCore&&) = default;
  PlantCore& operator=(PlantCore&&) = default;

  /// The outputs of the state at tick k (at t_k on `clock`).
  model::Outputs outputs(const TickClock& clock, Tick k) {
    return model_->outputs(clock.seconds(k), state_, rotor_input_, environment(k));
  }
  /// The sensor messages of tick k's outputs `y` (stamped `stamp`), and which sensors have a sample
  /// due (all of them without realism). A tick measured twice (a lockstep repeat) gives the same sample.
  PlantRealism::Due sense(Tick k, const model::Outputs& y, const msg::Time& stamp, msg::PoseStamped& pose,
                          msg::TwistStamped& twist, msg::Imu& imu) {
    write_sensor_messages(y, stamp, pose, twist, imu);
    if (realism_) return measure(k, y, pose, twist, imu);
    return {true, true, true};
  }
  /// What the sensors make of the outputs (noise, rates, latency) in messages written from them;
  /// with realism only (has_realism()).
  PlantRealism::Due measure(Tick k, const model::Outputs& y, msg::PoseStamped& pose, msg::TwistStamped& twist,
                            msg::Imu& imu) {
    return realism_->measure(k, y, pose, twist, imu);
  }
  bool has_realism() const { return static_cast<bool>(realism_); }

  /// The extra sensors of tick k's outputs `y` (in tick order; a tick again draws nothing new): whether
  /// any has a sample due at k. False without extra sensors.
  bool sense_extra(Tick k, const model::Outputs& y) { return extra_ && extra_->step(k, y); }
  /// The extra sensors' newest samples; null when the vehicle carries none.
  const sensors::Suite* extra_sensors() const { return extra_.get(); }

  /// A command message received during tick k: checked (sim::check_command against the vehicle's
  /// omega_max: a rejected one changes nothing, an out-of-range one is clamped), then queued to take
  /// effect at tick k + delay_ticks. Returns the check, for the caller's statistics.
  /// A command at another level (its layout names it: msg::command_level_name) is checked as that
  /// level's values and queued at its level.
  [[gnu::always_inline]] CommandCheck take_command(Tick k, Tick delay_ticks, const msg::Float64MultiArray& m) {
    const CommandCheck check = check_command(m, model_->params().motor.omega_max_rad_s, model_->rotor_count());
    take_checked(k, delay_ticks, check);
    return check;
  }
  /// A command already checked (check_command, e.g. of a typed command's values): queued unless rejected.
  void take_checked(Tick k, Tick delay_ticks, const CommandCheck& check) {
    if (check.verdict() != CommandVerdict::kRejected) queue(k, delay_ticks, check.omega_rad_s, check.level);
  }
  /// The upper end of the rotor speeds a command is checked against [rad/s].
  double omega_max_rad_s() const { return model_->params().motor.omega_max_rad_s; }
  /// How many rotor speeds a rotor-speed command holds: the vehicle's rotor count.
  int rotor_count() const { return model_->rotor_count(); }
  /// A valid command (speeds within [0, omega_max]; or 4 finite values of another level) received
  /// during tick k takes effect at tick k + delay_ticks.
  void queue(Tick k, Tick delay_ticks, const model::RotorVector& values,
             control::CommandLevel level = control::CommandLevel::kRotorSpeeds) {
    last_valid_tick_ = k;
    Pending& p = pending_.emplace_back();  // filled in place: no copy of the rotor vector
    p.effective_tick = k + delay_ticks;
    model::assign_rotors(p.omega, values);
    p.level = level;
  }
  /// The inner loops' gains (InnerLoopParams::for_vehicle when never set): checked for the vehicle and
  /// the plant period, std::invalid_argument naming the gain that does not fit.
  void set_inner_loops(const control::InnerLoopParams& params) {
    inner_ = std::make_unique<Inner>(Inner{control::InnerLoops(model_->params(), params, period_s_), {}});
  }
  /// The inner loops flying a level command (made at the first such command when never set); null
  /// before.
  const control::InnerLoops* inner_loops() const { return inner_ ? &inner_->loops : nullptr; }
  /// The level command held (level kRotorSpeeds: the rotor speeds are latched as they came).
  const control::LevelCommand& held() const { return held_; }
  /// What the inner loops decided for the current tick (meaningful while held() is above rotor speeds).
  const control::InnerLoopOutput* inner_output() const { return inner_ ? &inner_->last : nullptr; }
  /// Latches the newest command due by tick k (the others due are dropped); false when none is due.
  bool latch_due(Tick k) {
    const std::size_t first = pending_head_;
    while (pending_head_ < pending_.size() && pending_[pending_head_].effective_tick <= k) ++pending_head_;
    const bool latched = pending_head_ > first;
    if (latched) {  // the newest one due
      const Pending& p = pending_[pending_head_ - 1];
      if (p.level == control::CommandLevel::kRotorSpeeds) {
        held_.level = p.level;
        set_latched(p.omega);
      } else {
        held_ = {p.level, p.omega.head<4>()};
      }
    }
    if (held_.level != control::CommandLevel::kRotorSpeeds) fly_held();
    if (pending_head_ == pending_.size()) {
      pending_.clear();  // keeps the capacity
      pending_head_ = 0;
    } else if (pending_head_ > 64 && pending_head_ * 2 > pending_.size()) {
      pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(pending_head_));
      pending_head_ = 0;
    }
    return latched;
  }
  /// Latches a command: the speeds and, formed once here, the model's rotor input.
  void set_latched(const model::RotorVector& omega_rad_s) {
    model::assign_rotors(latched_, omega_rad_s);
    model_->rotor_input(omega_rad_s, rotor_input_);  // clamped and turned into a wrench once per latch
  }
  /// The command acting over [t_k, t_k+1): the newest due by tick k (latch_due), then the watchdog:
  /// when limit_ns > 0 and the command's age `age_ns` (command_age_ns in simulated time; a host in
  /// real time measures it on its receipt clock) has reached it, the command is stale and kStop
  /// latches every motor at omega_min. Returns whether it is stale.
  bool latch(Tick k, std::int64_t age_ns, std::int64_t limit_ns, WatchdogPolicy policy) {
    latch_due(k);
    const bool stale = limit_ns > 0 && age_ns >= limit_ns;
    if (stale && policy == WatchdogPolicy::kStop) latch_omega_min();
    return stale;
  }
  /// Latches every motor at the vehicle's omega_min_rad_s (the watchdog's stop policy).
  void latch_omega_min() {
    held_.level = control::CommandLevel::kRotorSpeeds;
    set_latched(model::RotorVector::Constant(model_->rotor_count(), model_->params().motor.omega_min_rad_s));
  }
  /// Time [ns] at tick k since the tick of the newest valid command (0 before any: from tick 0).
  std::int64_t command_age_ns(const TickClock& clock, Tick k) const {
    return clock.ns(k - std::min(last_valid_tick_, k));
  }
  /// Integrates the state from t_k to t_k+1 under the latched command, in `substeps` RK4 steps.
  void integrate(const TickClock& clock, Tick k, int substeps) {
    model_->step(state_, clock.seconds(k), rotor_input_, clock.period_s(), substeps, environment(k));
  }

  /// Asks the CPU to load the command queue's buffer, the one part of a tick's data outside the
  /// object (a batch steps many plants in turn, each long out of the cache).
  void prefetch() const { __builtin_prefetch(pending_.data()); }

  const model::Quadrotor& model() const { return *model_; }
  const model::State& state() const { return state_; }
  /// The state, for dynamics computed elsewhere to report (PlantNode's external dynamics).
  model::State& state() { return state_; }
  const model::RotorVector& latched() const { return latched_; }

 private:
  const model::Environment* environment(Tick k) { return realism_ ? &realism_->environment(k) : nullptr; }
  /// The held level command through the inner loops on the current state, latched for this tick.
  void fly_held() {
    if (!inner_) set_inner_loops(control::InnerLoopParams::for_vehicle(model_->params(), period_s_));
    inner_->last = inner_->loops.step(held_, state_);
    set_latched(inner_->last.allocation.omega_rad_s);
  }
  struct Inner {
    control::InnerLoops loops;
    control::InnerLoopOutput last;
  };

  std::optional<model::Quadrotor> model_;  ///< optional only to be default-constructible (a batch's array)
  model::State state_;
  model::RotorVector latched_ = model::RotorVector::Zero(4);  ///< the command acting over [t_k, t_k+1)
  model::RotorInput rotor_input_;                             ///< latched_ as the model applies it
  Tick last_valid_tick_ = 0;                                  ///< tick during which the newest valid command arrived
  double period_s_ = 0.0;                                     ///< the plant period the inner loops are designed for
  control::LevelCommand held_;                                ///< the level command held (rotor speeds: latched_ is it)
  std::unique_ptr<Inner> inner_;                              ///< the inner loops, made at the first level command
  struct Pending {
    Tick effective_tick;
    model::RotorVector omega;  ///< rotor speeds (one per rotor), or the 4 values of `level`
    control::CommandLevel level;
  };
  // Commands waiting for their tick, oldest first from pending_head_. A vector whose consumed front is
  // dropped in place (no allocation per command once its capacity suffices; a std::deque allocates a
  // block every few commands).
  std::vector<Pending> pending_;
  std::size_t pending_head_ = 0;
  /// Present when the realism or the vehicle's drag asks for it; null keeps the paper's plant.
  std::unique_ptr<PlantRealism> realism_;
  /// The magnetometer, barometer, GNSS configured; null for none (held out of line: a batch's plant
  /// stays the few cache lines a step of many vehicles touches).
  std::unique_ptr<sensors::Suite> extra_;
};

}  // namespace quadcosim::sim
