#include "io/mcap_recorder.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "io/ros2_cdr.hpp"
#include "sim/messages.hpp"

namespace quadcosim::io {

namespace {

template <class T>
std::int64_t stamp_of(const T& m, std::int64_t fallback) {
  if constexpr (std::is_same_v<T, msg::Clock>) {
    return m.clock.to_ns();
  } else if constexpr (std::is_same_v<T, msg::Float64MultiArray>) {
    const std::int64_t s = msg::command_stamp_ns(m);
    return s >= 0 ? s : fallback;
  } else {
    return m.header.stamp.to_ns();
  }
}

}  // namespace

McapRecorder::McapRecorder(const std::string& path, sim::Transport& transport, const sim::Topics& topics,
                           const std::vector<std::string>& only)
    : writer_(path, McapOptions{"ros2", 64 * 1024, true}) {  // small chunks: little to lose on a crash
  add<msg::Clock>(transport, topics.clock, only);
  add<msg::PoseStamped>(transport, topics.pose, only);
  add<msg::TwistStamped>(transport, topics.velocity, only);
  add<msg::Imu>(transport, topics.imu, only);
  add<msg::ControllerStatus>(transport, topics.controller_status, only);
  add<msg::PlantStatus>(transport, topics.plant_status, only);
  add<msg::Float64MultiArray>(transport, topics.motor_commands, only);
}

McapRecorder::~McapRecorder() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports errors when called explicitly
  }
}

template <class T>
void McapRecorder::add(sim::Transport& transport, const std::string& topic, const std::vector<std::string>& only) {
  if (!only.empty() && std::find(only.begin(), only.end(), topic) == only.end()) return;
  const std::string type(T::kRosType);
  const std::uint16_t schema = writer_.add_schema(type, "ros2msg", ros2msg_definition(type));
  const std::uint16_t id =
      writer_.add_channel(topic, schema, "cdr", {{"offered_qos_profiles", ros2_offered_qos_profiles(10, true)}});
  const std::size_t index = channels_.size();
  channels_.push_back({topic, type, id});
  transport.subscribe<T>(topic, [this, index](const T& m) {
    const std::int64_t t = stamp_of(m, last_stamp_ns_);
    bool stamped = true;  // the message carries its own time (header, clock, or command label)
    if constexpr (std::is_same_v<T, msg::Float64MultiArray>) stamped = msg::command_stamp_ns(m) >= 0;
    ChannelInfo& c = channels_[index];
    // Lockstep may repeat a tick (a republished sample or its repeated answer): one copy is recorded,
    // so the file does not depend on whether a repeat happened.
    if (stamped && c.newest_ns >= 0 && t <= c.newest_ns) {
      ++repeats_;
      return;
    }
    if (stamped) c.newest_ns = t;
    if constexpr (!std::is_same_v<T, msg::Float64MultiArray>) last_stamp_ns_ = std::max(last_stamp_ns_, t);
    push(static_cast<std::uint16_t>(index), t, to_cdr(m));
  });
}

void McapRecorder::push(std::uint16_t channel, std::int64_t t_ns, std::vector<std::uint8_t> cdr) {
  pending_.push_back({t_ns, channel, arrivals_++, std::move(cdr)});
}

void McapRecorder::flush_before(std::int64_t sim_ns) {
  auto ready =
      std::stable_partition(pending_.begin(), pending_.end(), [sim_ns](const Pending& p) { return p.t_ns < sim_ns; });
  std::sort(pending_.begin(), ready, [](const Pending& a, const Pending& b) {
    if (a.t_ns != b.t_ns) return a.t_ns < b.t_ns;
    if (a.channel != b.channel) return a.channel < b.channel;
    return a.arrival < b.arrival;
  });
  for (auto it = pending_.begin(); it != ready; ++it) {
    ChannelInfo& c = channels_[it->channel];
    const auto t = static_cast<std::uint64_t>(std::max<std::int64_t>(it->t_ns, 0));
    writer_.write(c.id, ++c.sequence, t, t, it->cdr.data(), it->cdr.size());
    ++c.count;
    ++written_;
    if (first_ns_ < 0 || static_cast<std::int64_t>(t) < first_ns_) first_ns_ = static_cast<std::int64_t>(t);
    last_ns_ = std::max(last_ns_, static_cast<std::int64_t>(t));
  }
  pending_.erase(pending_.begin(), ready);
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
  std::ofstream y(dir + "/metadata.yaml");
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
    for (char ch : ros2_offered_qos_profiles(10, true)) y << (ch == '\n' ? std::string("\\n") : std::string(1, ch));
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
  if (!y) throw std::runtime_error(dir + "/metadata.yaml: write failed");
}

}  // namespace quadcosim::io
