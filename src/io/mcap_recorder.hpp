// Records a run's ROS 2 traffic as MCAP (ROS 2 profile: ros2msg schemas, cdr messages) with log
// time = simulated time, and writes the metadata.yaml that lets `ros2 bag` open the run directory.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "io/mcap_writer.hpp"
#include "model/vehicle_params.hpp"
#include "sensors/sensor_set.hpp"
#include "sim/messages.hpp"
#include "sim/topic_qos.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::io {

/// A message's time [ns] as the recorder stamps it (and the live Foxglove view serves it): the header
/// stamp; /clock's clock; a TFMessage's first transform's stamp; motor commands the time in their
/// label. `fallback` where the message has none (an empty TFMessage, an unlabelled command).
template <class T>
std::int64_t message_time_ns(const T& m, std::int64_t fallback) {
  if constexpr (std::is_same_v<T, msg::Clock>) {
    return m.clock.to_ns();
  } else if constexpr (std::is_same_v<T, msg::TFMessage>) {
    return m.transforms.empty() ? fallback : m.transforms.front().header.stamp.to_ns();
  } else if constexpr (std::is_same_v<T, msg::Float64MultiArray>) {
    const std::int64_t s = msg::command_stamp_ns(m);
    return s >= 0 ? s : fallback;
  } else {
    return m.header.stamp.to_ns();
  }
}

/// One message that describes a vehicle: sent once and kept for late readers (transient local).
struct LatchedMessage {
  std::string topic;
  std::string type;  ///< "pkg/msg/Type"
  std::vector<std::uint8_t> cdr;
};

/// What describes the vehicle in namespace `ns` to a 3D view, stamped `t_ns`, in this order:
/// <ns>/robot_description (std_msgs/String, its URDF), /tf_static (base_link -> rotors) and <ns>/scene
/// (foxglove_msgs/SceneUpdate drawing it frame-locked to <ns>/base_link); sim/vehicle_description.hpp
/// builds them. What McapRecorder::record_vehicle records and `--foxglove` serves latched.
std::vector<LatchedMessage> vehicle_description_messages(const model::VehicleParams& vehicle, const std::string& ns,
                                                         std::int64_t t_ns);

class McapRecorder {
 public:
  /// Opens `path` and subscribes, through `transport`, to the vehicle's topics: /clock, Pose,
  /// Velocity, Imu, motor_commands, controller_status, plant_status and /tf. Throws
  /// std::runtime_error naming the path.
  /// `only`, when not empty, limits the recording to those topic names.
  McapRecorder(const std::string& path, sim::Transport& transport, const sim::Topics& topics,
               const std::vector<std::string>& only = {});
  ~McapRecorder();
  McapRecorder(const McapRecorder&) = delete;
  McapRecorder& operator=(const McapRecorder&) = delete;

  /// Writes every buffered message stamped before `sim_ns` [ns], in (time, channel, arrival) order.
  /// Messages are stamped with their header time (motor commands: the time in their label, or the
  /// last header time seen); buffering makes the file independent of the order messages arrive in.
  /// A stamped message no newer than the last one its writer sent on its channel is a repeat and is
  /// not recorded; every writer's messages are recorded, a stranger's too, and none is dropped for
  /// another writer's stamps.
  void flush_before(std::int64_t sim_ns);
  /// How long [ns] messages stay buffered behind the current simulated time, so late arrivals of a
  /// tick still go in order (several ticks; lockstep answers within one).
  static constexpr std::int64_t kHoldNs = 100'000'000;
  /// flush_before(now_ns - kHoldNs): the call to make once per tick.
  void flush_settled(std::int64_t now_ns) { flush_before(now_ns - kHoldNs); }

  /// Records, at `t_ns`, what describes the vehicle in namespace `ns` (sim/vehicle_description.hpp):
  /// <ns>/robot_description and /tf_static as the plant publishes them once, and <ns>/scene, a
  /// foxglove_msgs/msg/SceneUpdate drawing it frame-locked to <ns>/base_link. Written from the vehicle
  /// parameters, not taken from the wire: the file does not depend on when a late (transient-local)
  /// sample arrives, so in-process and DDS recordings stay identical. Call once, before the first
  /// flush; topics outside `only` (constructor) are skipped.
  void record_vehicle(const model::VehicleParams& vehicle, const std::string& ns, std::int64_t t_ns);

  /// Also records the topics of the extra sensors `set` configures (magnetometer, barometer, GNSS:
  /// sim/sensor_wire.hpp) under `ns`. Call before the first tick; topics outside `only` are skipped.
  void record_sensors(sim::Transport& transport, const std::string& ns, const sensors::SensorSet& set);

  /// Newest message time seen so far [ns] (0 before any).
  std::int64_t newest_ns() const { return last_stamp_ns_; }

  /// Writes everything left and finishes the file (summary, footer). Idempotent.
  void close();
  /// Writes `dir`/metadata.yaml describing the file for `ros2 bag info|play` (call after close).
  void write_bag_metadata(const std::string& dir, const std::string& mcap_file_name) const;

  std::uint64_t messages() const { return written_; }
  /// Repeated samples (same channel and writer, stamp not newer than its last) not recorded again.
  std::uint64_t repeats() const { return repeats_; }

 private:
  struct Pending {
    std::int64_t t_ns;
    std::uint16_t channel;
    std::uint64_t arrival;
    std::vector<std::uint8_t> cdr;
  };
  /// The order messages are written in, reversed (pending_'s heap order): (time, channel, arrival).
  static bool later(const Pending& a, const Pending& b);
  struct ChannelInfo {
    std::string topic, type;
    std::uint16_t id;
    sim::TopicQos qos;
    std::uint64_t count = 0;
    std::uint32_t sequence = 0;
    /// Newest stamp recorded per writer (a stranger's stamps say nothing about the run's own
    /// messages: each writer's repeats are its own); a handful of writers per channel.
    std::vector<std::pair<sim::SenderId, std::int64_t>> newest_by_sender;
    /// tf2_msgs/TFMessage: newest stamp per writer and child frame (many vehicles share /tf, each its
    /// own frame)
    std::map<std::pair<sim::SenderId, std::string>, std::int64_t> newest_by_frame;
  };
  /// The channel of `topic` with the schema of `type` ("pkg/msg/Type"); its index in channels_.
  std::size_t open_channel(const std::string& topic, const std::string& type, sim::TopicQos qos);
  /// Records `topic`; `lazy`: its channel is opened at its first message (the typed command topics: a
  /// recording shows the one a controller used, not seven empty ones).
  template <class T>
  void add(sim::Transport& transport, const std::string& topic, bool lazy = false);
  bool wanted(const std::string& topic) const;
  void push(std::uint16_t channel, std::int64_t t_ns, std::vector<std::uint8_t> cdr);

  McapWriter writer_;
  std::vector<std::string> only_;
  std::vector<ChannelInfo> channels_;  // indexed by position, not by MCAP id
  std::vector<Pending> pending_;       ///< a heap by later(): the earliest at the front
  std::uint64_t arrivals_ = 0, written_ = 0, repeats_ = 0;
  std::int64_t last_stamp_ns_ = 0;
  std::int64_t first_ns_ = -1, last_ns_ = -1;
  bool closed_ = false;
};

}  // namespace quadcosim::io
