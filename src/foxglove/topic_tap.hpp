// The vehicle's topics as Foxglove channels: subscribes through a node's transport to what the MCAP
// recorder records (io/mcap_recorder.hpp) and hands each message to a foxglove::Server as the CDR bytes
// the recorder writes, stamped with its header time (simulated); and the vehicle's description
// (URDF, /tf_static, scene) as latched channels, so Foxglove's 3D panel draws it.
#pragma once

#include <cstdint>
#include <string>

#include "foxglove/server.hpp"
#include "model/vehicle_params.hpp"
#include "sensors/sensor_set.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::foxglove {

/// Adds one channel per topic of `topics` (/clock, Pose, Velocity, Imu, controller_status,
/// plant_status, motor_commands, /tf, the typed commands /<ns>/cmd/<level>) to `server` (before its
/// start()) and subscribes to each through
/// `transport`. The subscriptions cost one relaxed atomic load per message while no client subscribes
/// (unless ServerOptions::keep_last). `server` must outlive the transport's deliveries.
void serve_vehicle_topics(Server& server, sim::Transport& transport, const sim::Topics& topics);

/// The same for the topics of the extra sensors `set` configures (magnetometer, barometer, GNSS:
/// sim/sensor_wire.hpp) under the vehicle's namespace `ns`.
void serve_sensor_topics(Server& server, sim::Transport& transport, const std::string& ns,
                         const sensors::SensorSet& set);

/// Adds the latched channels a 3D panel draws the vehicle in namespace `ns` from: <ns>/robot_description,
/// /tf_static and <ns>/scene, each holding its one message stamped `t_ns` (the run's start) and given
/// to every client as it subscribes. The same bytes as McapRecorder::record_vehicle records
/// (io::vehicle_description_messages), built from the parameters, not taken from the wire: a plant's
/// node and its controller's serve the same, whenever a client comes. Before the server's start().
void serve_vehicle_description(Server& server, const model::VehicleParams& vehicle, const std::string& ns,
                               std::int64_t t_ns);

}  // namespace quadcosim::foxglove
