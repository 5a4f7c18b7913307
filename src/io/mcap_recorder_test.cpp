// McapRecorder: repeats of a lockstep tick are recorded once; unlabelled commands are all kept.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/mcap_recorder.hpp"
#include "io/mcap_writer.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/level_messages.hpp"
#include "sim/messages.hpp"

namespace quadcosim::io {
namespace {

// MCAP's CRC-32: the standard check value of "123456789" (0xCBF43926), and a bit at a time (the
// polynomial's definition) over every length 0..300 from every alignment 0..7.
TEST(McapCrcTest, MatchesTheCheckValueAndABitwiseCrc) {
  const std::string check = "123456789";
  EXPECT_EQ(mcap_crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0xCBF43926u);
  EXPECT_EQ(mcap_crc32({}), 0u);
  std::vector<std::uint8_t> bytes(320);
  std::mt19937 rng(3);
  for (std::uint8_t& b : bytes) b = static_cast<std::uint8_t>(rng());
  for (std::size_t start = 0; start < 8; ++start) {
    for (std::size_t n = 0; n <= 300; ++n) {
      std::uint32_t c = 0xFFFFFFFFu;
      for (std::size_t i = start; i < start + n; ++i) {
        c ^= bytes[i];
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
      }
      ASSERT_EQ(mcap_crc32({bytes.data() + start, n}), c ^ 0xFFFFFFFFu) << "start " << start << ", " << n << " bytes";
    }
  }
}

TEST(McapRecorderTest, RecordsARepeatedTickOnceAndKeepsUnlabelledCommands) {
  const auto dir = std::filesystem::temp_directory_path() / ("mcap_rec_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  sim::InProcessTransport bus;
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  McapRecorder rec((dir / "run.mcap").string(), bus, topics);
  auto pose = bus.advertise<msg::PoseStamped>(topics.pose);
  auto cmd = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);

  msg::PoseStamped p;
  p.header.stamp = msg::Time::from_ns(10'000'000);
  pose.publish(p);
  pose.publish(p);  // the plant republished tick 1
  p.header.stamp = msg::Time::from_ns(20'000'000);
  pose.publish(p);

  msg::Float64MultiArray labelled;
  labelled.data = {1, 2, 3, 4};
  labelled.dim = {{msg::command_label(20'000'000), 4, 4}};
  cmd.publish(labelled);
  cmd.publish(labelled);         // the controller answered the repeat again
  msg::Float64MultiArray plain;  // a foreign controller: no label, all kept
  plain.data = {5, 6, 7, 8};
  cmd.publish(plain);
  cmd.publish(plain);

  rec.close();
  EXPECT_EQ(rec.messages(), 2u + 1u + 2u);
  EXPECT_EQ(rec.repeats(), 2u);
  rec.write_bag_metadata(dir.string(), "run.mcap");
  std::ifstream y(dir / "metadata.yaml");
  const std::string meta((std::istreambuf_iterator<char>(y)), std::istreambuf_iterator<char>());
  EXPECT_NE(meta.find("message_count: 5"), std::string::npos) << meta;
  std::filesystem::remove_all(dir);
}

// One /tf carries every vehicle of a swarm: a repeat is a transform no newer than the last of the same
// child frame, not of the channel. The vehicle's description is written at the time given, tf2's and
// robot_state_publisher's QoS in the bag metadata.
TEST(McapRecorderTest, TfRepeatsArePerChildFrameAndTheVehicleIsDescribedOnce) {
  const auto dir = std::filesystem::temp_directory_path() / ("mcap_tf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  sim::InProcessTransport bus;
  const sim::Topics topics = sim::Topics::for_namespace("/uav0000");
  McapRecorder rec((dir / "run.mcap").string(), bus, topics);
  rec.record_vehicle(model::VehicleParams{}, "/uav0000", 0);
  auto tf = bus.advertise<msg::TFMessage>(topics.tf);
  auto one = [](const std::string& child, std::int64_t ns) {
    msg::TFMessage m;
    m.transforms.resize(1);
    m.transforms[0].header = {msg::Time::from_ns(ns), "world"};
    m.transforms[0].child_frame_id = child;
    return m;
  };
  tf.publish(one("uav0000/base_link", 0));
  tf.publish(one("uav0001/base_link", 0));  // same stamp, another vehicle: recorded
  tf.publish(one("uav0000/base_link", 0));  // a repeated tick: not
  tf.publish(one("uav0001/base_link", 10'000'000));
  tf.publish(one("uav0000/base_link", 10'000'000));
  rec.close();
  EXPECT_EQ(rec.messages(), 4u + 3u);  // and robot_description, /tf_static, the scene
  EXPECT_EQ(rec.repeats(), 1u);
  rec.write_bag_metadata(dir.string(), "run.mcap");
  std::ifstream y(dir / "metadata.yaml");
  const std::string meta((std::istreambuf_iterator<char>(y)), std::istreambuf_iterator<char>());
  for (const std::string want : {"name: /tf\n        type: tf2_msgs/msg/TFMessage",
                                 "name: /uav0000/robot_description\n        type: std_msgs/msg/String",
                                 "name: /tf_static\n        type: tf2_msgs/msg/TFMessage",
                                 "name: /uav0000/scene\n        type: foxglove_msgs/msg/SceneUpdate", "depth: 100\\n",
                                 "durability: transient_local"}) {
    EXPECT_NE(meta.find(want), std::string::npos) << want << "\n" << meta;
  }
  std::filesystem::remove_all(dir);
}

// A transport whose test says who sent each message (as DDS does with the writer's handle).
class SendersTransport final : public sim::Transport {
 public:
  template <class T>
  void deliver(const std::string& topic, const T& m, sim::SenderId sender) {
    for (auto& [t, d] : subs_) {
      if (t == topic) d(&m, sender);
    }
  }

 protected:
  std::function<void(const void*)> make_sink(const std::string&, const sim::TopicType&,
                                             const sim::QosChoice&) override {
    return [](const void*) {};
  }
  void add_subscription(const std::string& topic, const sim::TopicType& type, const sim::QosChoice& qos,
                        std::function<void(const void*)> d) override {
    add_subscription_with_sender(topic, type, qos, [d = std::move(d)](const void* m, sim::SenderId) { d(m); });
  }
  void add_subscription_with_sender(const std::string& topic, const sim::TopicType&, const sim::QosChoice&,
                                    std::function<void(const void*, sim::SenderId)> d) override {
    subs_.emplace_back(topic, std::move(d));
  }

 private:
  std::vector<std::pair<std::string, std::function<void(const void*, sim::SenderId)>>> subs_;
};

// A stranger's far-future stamp says nothing of the run's own messages: repeats are per writer, so
// every message of the run's own writer is recorded (and the stranger's too, once each).
TEST(McapRecorderTest, RepeatsArePerWriterSoAStrangersStampDropsNothing) {
  const auto dir = std::filesystem::temp_directory_path() / ("mcap_writers_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  SendersTransport bus;
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  McapRecorder rec((dir / "run.mcap").string(), bus, topics);
  constexpr sim::SenderId kOwn = 7, kStranger = 9;
  msg::ControllerStatus s;
  s.header.stamp = msg::Time::from_ns(2'000'000'000LL * 1'000'000'000LL);
  bus.deliver(topics.controller_status, s, kStranger);
  for (int k = 1; k <= 100; ++k) {
    s.header.stamp = msg::Time::from_ns(k * 20'000'000LL);
    bus.deliver(topics.controller_status, s, kOwn);
    if (k % 10 == 0) bus.deliver(topics.controller_status, s, kOwn);  // a repeat of the own writer's
  }
  bus.deliver(topics.controller_status, s, kStranger);  // older than the stranger's own newest: a repeat
  rec.close();
  EXPECT_EQ(rec.messages(), 100u + 1u);
  EXPECT_EQ(rec.repeats(), 10u + 1u);
  std::filesystem::remove_all(dir);
}

// A typed command topic is recorded from its first message on; the others stay out of the file.
TEST(McapRecorderTest, ATypedCommandTopicIsRecordedOnceItCarriesMessages) {
  const auto dir = std::filesystem::temp_directory_path() / ("mcap_typed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  sim::InProcessTransport bus;
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  McapRecorder rec((dir / "run.mcap").string(), bus, topics);
  auto ctbr = bus.advertise<msg::ThrustRates>("/drone/cmd/ctbr");
  msg::ThrustRates m;
  m.thrust_n = 19.2;
  for (int k = 0; k < 3; ++k) {
    m.header.stamp = msg::Time::from_ns(20'000'000 * k);
    ctbr.publish(m);
    ctbr.publish(m);  // a lockstep repeat: recorded once
  }
  rec.close();
  EXPECT_EQ(rec.messages(), 3u);
  rec.write_bag_metadata(dir.string(), "run.mcap");
  std::ifstream y(dir / "metadata.yaml");
  const std::string meta((std::istreambuf_iterator<char>(y)), std::istreambuf_iterator<char>());
  EXPECT_NE(meta.find("name: /drone/cmd/ctbr\n        type: quadcosim_msgs/msg/ThrustRates"), std::string::npos)
      << meta;
  EXPECT_EQ(meta.find("/drone/cmd/velocity"), std::string::npos) << "a typed topic without messages: no channel";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace quadcosim::io
