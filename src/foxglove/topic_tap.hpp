// The vehicle's topics as Foxglove channels: subscribes through a node's transport to what the MCAP
// recorder records (io/mcap_recorder.hpp) and hands each message to a foxglove::Server as the CDR bytes
// the recorder writes, stamped with its header time (simulated).
#pragma once

#include "foxglove/server.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::foxglove {

/// Adds one channel per topic of `topics` (/clock, Pose, Velocity, Imu, controller_status,
/// plant_status, motor_commands) to `server` (before its start()) and subscribes to each through
/// `transport`. The subscriptions cost one relaxed atomic load per message while no client subscribes
/// (unless ServerOptions::keep_last). `server` must outlive the transport's deliveries.
void serve_vehicle_topics(Server& server, sim::Transport& transport, const sim::Topics& topics);

}  // namespace quadcosim::foxglove
