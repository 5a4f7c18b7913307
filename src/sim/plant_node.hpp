// The plant as a node: integrates the model on integer ticks, publishes the paper's sensor topics and
// /clock, and takes rotor speed commands from /<ns>/motor_commands (zero-order hold).
#pragma once

#include <cstdint>
#include <vector>

#include "model/quadrotor.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

struct PlantOptions {
  TickClock clock;
  int substeps = 1;              ///< RK4 steps per plant tick
  int command_delay_ticks = 0;   ///< a command received during tick k takes effect at tick k + delay
  std::string frame_id = "world";
  /// Lockstep: a command labelled with a stamp older than the current tick answers an earlier tick
  /// (a repeat) and is dropped instead of overriding the current one.
  bool drop_stale_commands = false;
  /// Publish /clock. It is global, not namespaced: when one process hosts many plants, one of them
  /// publishes it.
  bool publish_clock = true;
};

struct PlantStats {
  std::uint64_t commands_received = 0;
  std::uint64_t commands_rejected = 0;  ///< wrong length or non-finite: ignored, last good one held
  std::uint64_t commands_stale = 0;     ///< lockstep repeats of an earlier tick's command, dropped
};

class PlantNode {
 public:
  PlantNode(Transport& transport, const Topics& topics, const model::VehicleParams& vehicle,
            const PlantOptions& options, const model::State& initial);

  /// Publishes /clock, Pose, Velocity and Imu for the state at tick k.
  void publish_outputs(Tick k);
  /// Fixes the command that acts over [t_k, t_k+1): the newest one whose delay has elapsed.
  void latch_command(Tick k);
  /// Integrates the state from t_k to t_k+1 under the latched command.
  void integrate(Tick k);

  const model::State& state() const { return state_; }
  const model::Quadrotor& model() const { return model_; }
  /// The command latched for the current interval, as received (before the model's clamping).
  const model::Vector4& applied_command() const { return applied_; }
  const PlantStats& stats() const { return stats_; }
  /// Stamp label [ns] of the newest accepted command (-1: unlabelled or none yet).
  std::int64_t last_command_stamp_ns() const { return last_command_stamp_ns_; }
  const PlantOptions& options() const { return options_; }
  Tick current_tick() const { return current_tick_; }

 private:
  void on_command(const msg::Float64MultiArray& m);

  model::Quadrotor model_;
  PlantOptions options_;
  model::State state_;
  Tick current_tick_ = 0;
  std::int64_t last_command_stamp_ns_ = -1;
  model::Vector4 applied_ = model::Vector4::Zero();
  struct Pending {
    Tick effective_tick;
    model::Vector4 omega;
  };
  // Commands waiting for their tick, oldest first from pending_head_. A vector whose consumed front is
  // dropped in place (no allocation per command once its capacity suffices; a std::deque allocates a
  // block every few commands).
  std::vector<Pending> pending_;
  std::size_t pending_head_ = 0;
  PlantStats stats_;
  Publisher<msg::Clock> clock_pub_;
  Publisher<msg::PoseStamped> pose_pub_;
  Publisher<msg::TwistStamped> velocity_pub_;
  Publisher<msg::Imu> imu_pub_;
};

}  // namespace quadcosim::sim
