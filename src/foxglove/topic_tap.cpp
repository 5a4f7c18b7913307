#include "foxglove/topic_tap.hpp"

#include <atomic>
#include <memory>
#include <string>

#include "io/mcap_recorder.hpp"
#include "io/ros2_cdr.hpp"
#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "sim/sensor_wire.hpp"

namespace quadcosim::foxglove {

namespace {

// The newest header time seen [ns]: the time of motor commands without a stamp in their label.
using Newest = std::shared_ptr<std::atomic<std::int64_t>>;

template <class T>
void serve(Server& server, sim::Transport& transport, const std::string& topic, const Newest& newest) {
  const std::string type(T::kRosType);
  const std::uint32_t channel = server.add_channel(topic, type, io::ros2msg_definition(type));
  transport.subscribe_tap<T>(topic, [&server, channel, newest](const T& m, sim::SenderId, sim::WireBytes wire) {
    // Motor commands without a label: the newest header time seen (as the recorder stamps them).
    const std::int64_t t = io::message_time_ns(m, newest->load(std::memory_order_relaxed));
    if constexpr (!std::is_same_v<T, msg::Float64MultiArray>) {
      std::int64_t seen = newest->load(std::memory_order_relaxed);
      while (t > seen && !newest->compare_exchange_weak(seen, t, std::memory_order_relaxed)) {
      }
    }
    if (!server.wanted(channel)) return;
    // The bytes the writer serialised where the transport has them (DDS), else encoded here.
    server.publish(channel, t, wire.empty() ? io::to_cdr(m) : std::vector<std::uint8_t>(wire.begin(), wire.end()));
  });
}

}  // namespace

void serve_vehicle_topics(Server& server, sim::Transport& transport, const sim::Topics& topics) {
  auto newest = std::make_shared<std::atomic<std::int64_t>>(0);
  serve<msg::Clock>(server, transport, topics.clock, newest);
  serve<msg::PoseStamped>(server, transport, topics.pose, newest);
  serve<msg::TwistStamped>(server, transport, topics.velocity, newest);
  serve<msg::Imu>(server, transport, topics.imu, newest);
  serve<msg::ControllerStatus>(server, transport, topics.controller_status, newest);
  serve<msg::PlantStatus>(server, transport, topics.plant_status, newest);
  serve<msg::Float64MultiArray>(server, transport, topics.motor_commands, newest);
  serve<msg::TFMessage>(server, transport, topics.tf, newest);
  // The typed commands (/<ns>/cmd/<level>), for a controller that commands on one of them.
  msg::for_each_level_message([&]<class T>() {
    serve<T>(server, transport, topics.level_commands[static_cast<std::size_t>(T::kLevel)], newest);
  });
}

void serve_sensor_topics(Server& server, sim::Transport& transport, const std::string& ns,
                         const sensors::SensorSet& set) {
  auto newest = std::make_shared<std::atomic<std::int64_t>>(0);
  sim::for_each_sensor_topic(set, ns,
                             [&]<class T>(const std::string& topic) { serve<T>(server, transport, topic, newest); });
}

void serve_vehicle_description(Server& server, const model::VehicleParams& vehicle, const std::string& ns,
                               std::int64_t t_ns) {
  for (io::LatchedMessage& m : io::vehicle_description_messages(vehicle, ns, t_ns)) {
    server.add_latched_channel(m.topic, m.type, io::ros2msg_definition(m.type), t_ns, std::move(m.cdr));
  }
}

}  // namespace quadcosim::foxglove
