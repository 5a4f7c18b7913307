#include "io/mcap_recorder.hpp"

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "io/output_folder.hpp"
#include "io/ros2_cdr.hpp"
#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "sim/sensor_wire.hpp"
#include "sim/vehicle_description.hpp"

namespace quadcosim::io {

namespace {
constexpr std::size_t kUnopened = static_cast<std::size_t>(-1);  ///< a lazy channel before its first message
}  // namespace

std::vector<LatchedMessage> vehicle_description_messages(const model::VehicleParams& vehicle, const std::string& ns,
                                                         std::int64_t t_ns) {
  const sim::Topics topics = sim::Topics::for_namespace(ns);
  const sim::VehicleDescription d = sim::describe_vehicle(vehicle, ns, msg::Time::from_ns(t_ns));
  std::vector<LatchedMessage> out;
  out.push_back({topics.robot_description, std::string(msg::String::kRosType), to_cdr(d.urdf)});
  out.push_back({topics.tf_static, std::string(msg::TFMessage::kRosType), to_cdr(d.rotors)});
  out.push_back({topics.scene, std::string(msg::SceneUpdate::kRosType), to_cdr(d.scene)});
  return out;
}

McapRecorder::McapRecorder(const std::string& path, sim::Transport& transport, const sim::Topics& topics,
                           const std::vector<std::string>& only)
    : writer_(path, McapOptions{"ros2", 64 * 1024, true}), only_(only) {  // small chunks: little to lose on a crash
  add<msg::Clock>(transport, topics.clock);
  add<msg::PoseStamped>(transport, topics.pose);
  add<msg::TwistStamped>(transport, topics.velocity);
  add<msg::Imu>(transport, topics.imu);
  add<msg::ControllerStatus>(transport, topics.controller_status);
  add<msg::PlantStatus>(transport, topics.plant_status);
  add<msg::Float64MultiArray>(transport, topics.motor_commands);
  add<msg::TFMessage>(transport, topics.tf);
  msg::for_each_level_message(
      [&]<class T>() { add<T>(transport, topics.level_commands[static_cast<std::size_t>(T::kLevel)], /*lazy=*/true); });
}

bool McapRecorder::wanted(const std::string& topic) const {
  return only_.empty() || std::find(only_.begin(), only_.end(), topic) != only_.end();
}

void McapRecorder::record_vehicle(const model::VehicleParams& vehicle, const std::string& ns, std::int64_t t_ns) {
  for (LatchedMessage& m : vehicle_description_messages(vehicle, ns, t_ns)) {
    if (!wanted(m.topic)) continue;
    push(static_cast<std::uint16_t>(open_channel(m.topic, m.type, sim::TopicQos::for_topic(m.topic))), t_ns,
         std::move(m.cdr));
  }
}

McapRecorder::~McapRecorder() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports errors when called explicitly
  }
}

std::size_t McapRecorder::open_channel(const std::string& topic, const std::string& type, sim::TopicQos qos) {
  const std::uint16_t schema = writer_.add_schema(type, "ros2msg", ros2msg_definition(type));
  const std::uint16_t id = writer_.add_channel(
      topic, schema, "cdr",
      {{"offered_qos_profiles",
        ros2_offered_qos_profiles(static_cast<std::uint32_t>(qos.depth), qos.reliable, qos.transient_local)}});
  ChannelInfo c;
  c.topic = topic;
  c.type = type;
  c.id = id;
  c.qos = qos;
  channels_.push_back(std::move(c));
  return channels_.size() - 1;
}

template <class T>
void McapRecorder::add(sim::Transport& transport, const std::string& topic, bool lazy) {
  if (!wanted(topic)) return;
  // The channel's index in channels_; lazy: opened at the first message.
  auto at = std::make_shared<std::size_t>(
      lazy ? kUnopened : open_channel(topic, std::string(T::kRosType), sim::TopicQos::for_topic(topic)));
  transport.subscribe_tap<T>(topic, [this, at, topic](const T& m, sim::SenderId sender, sim::WireBytes wire) {
    if (*at == kUnopened) *at = open_channel(topic, std::string(T::kRosType), sim::TopicQos::for_topic(topic));
    const std::size_t index = *at;
    const std::int64_t t = message_time_ns(m, last_stamp_ns_);
    bool stamped = true;  // the message carries its own time (header, clock, or command label)
    if constexpr (std::is_same_v<T, msg::Float64MultiArray>) stamped = msg::command_stamp_ns(m) >= 0;
    ChannelInfo& c = channels_[index];
    // Lockstep may repeat a tick (a republished sample or its repeated answer): one copy is recorded,
    // so the file does not depend on whether a repeat happened.
    if constexpr (std::is_same_v<T, msg::TFMessage>) {  // per child frame: one /tf carries many vehicles
      if (!m.transforms.empty()) {
        auto [it, first] = c.newest_by_frame.try_emplace({sender, m.transforms.front().child_frame_id}, t);
        if (!first && t <= it->second) {
          ++repeats_;
          return;
        }
        it->second = t;
      }
    } else {
      if (stamped) {
        auto it = std::find_if(c.newest_by_sender.begin(), c.newest_by_sender.end(),
                               [sender](const auto& e) { return e.first == sender; });
        if (it == c.newest_by_sender.end()) {
          c.newest_by_sender.emplace_back(sender, t);
        } else if (t <= it->second) {
          ++repeats_;
          return;
        } else {
          it->second = t;
        }
      }
    }
    if constexpr (!std::is_same_v<T, msg::Float64MultiArray>) last_stamp_ns_ = std::max(last_stamp_ns_, t);
    // The bytes the writer serialised where the transport has them (DDS), else encoded here once.
    push(static_cast<std::uint16_t>(index), t,
         wire.empty() ? to_cdr(m) : std::vector<std::uint8_t>(wire.begin(), wire.end()));
  });
}

// pending_ is a heap whose front is the earliest message in (time, channel, arrival) order: a tick
// writes its settled messages without looking at the ~100 ms of newer ones buffered behind them.
bool McapRecorder::later(const Pending& a, const Pending& b) {
  if (a.t_ns != b.t_ns) return a.t_ns > b.t_ns;
  if (a.channel != b.channel) return a.channel > b.channel;
  return a.arrival > b.arrival;
}

void McapRecorder::push(std::uint16_t channel, std::int64_t t_ns, std::vector<std::uint8_t> cdr) {
  pending_.push_back({t_ns, channel, arrivals_++, std::move(cdr)});
  std::push_heap(pending_.begin(), pending_.end(), later);
}

void McapRecorder::flush_before(std::int64_t sim_ns) {
  while (!pending_.empty() && pending_.front().t_ns < sim_ns) {
    std::pop_heap(pending_.begin(), pending_.end(), later);
    const Pending& p = pending_.back();
    ChannelInfo& c = channels_[p.channel];
    const auto t = static_cast<std::uint64_t>(std::max<std::int64_t>(p.t_ns, 0));
    writer_.write(c.id, ++c.sequence, t, t, p.cdr.data(), p.cdr.size());
    ++c.count;
    ++written_;
    if (first_ns_ < 0 || static_cast<std::int64_t>(t) < first_ns_) first_ns_ = static_cast<std::int64_t>(t);
    last_ns_ = std::max(last_ns_, static_cast<std::int64_t>(t));
    pending_.pop_back();
  }
}

void McapRecorder::close() {
  if (closed_) return;
  closed_ = true;
  flush_before(INT64_MAX);
  writer_.close();
}

void McapRecorder::write_bag_metadata(const std::string& dir, const std::string& file) const {
  const std::int64_t start = first_ns_ < 0 ? 0 : first_ns_;
  const std::int64_t duration = last_ns_ < 0 ? 0 : last_ns_ - start;
  std::ostringstream y;
  y << "rosbag2_bagfile_information:\n"
    << "  version: 5\n"
    << "  storage_identifier: mcap\n"
    << "  duration:\n    nanoseconds: " << duration << "\n"
    << "  starting_time:\n    nanoseconds_since_epoch: " << start << "\n"
    << "  message_count: " << written_ << "\n"
    << "  topics_with_message_count:\n";
  for (const auto& c : channels_) {
    y << "    - topic_metadata:\n"
      << "        name: " << c.topic << "\n"
      << "        type: " << c.type << "\n"
      << "        serialization_format: cdr\n"
      << "        offered_qos_profiles: \"";
    for (char ch :
         ros2_offered_qos_profiles(static_cast<std::uint32_t>(c.qos.depth), c.qos.reliable, c.qos.transient_local)) {
      y << (ch == '\n' ? std::string("\\n") : std::string(1, ch));
    }
    y << "\"\n"
      << "      message_count: " << c.count << "\n";
  }
  y << "  compression_format: \"\"\n"
    << "  compression_mode: \"\"\n"
    << "  relative_file_paths:\n    - " << file << "\n"
    << "  files:\n"
    << "    - path: " << file << "\n"
    << "      starting_time:\n        nanoseconds_since_epoch: " << start << "\n"
    << "      duration:\n        nanoseconds: " << duration << "\n"
    << "      message_count: " << written_ << "\n";
  write_file_atomically(dir + "/metadata.yaml", y.str());  // throws "…/metadata.yaml: write failed (why)"
}

void McapRecorder::record_sensors(sim::Transport& transport, const std::string& ns, const sensors::SensorSet& set) {
  sim::for_each_sensor_topic(set, ns, [&]<class T>(const std::string& topic) { add<T>(transport, topic); });
}

}  // namespace quadcosim::io
