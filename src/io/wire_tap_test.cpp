// Transport::subscribe_tap: over DDS a tap gets the bytes the writer serialised (Cyclone's, its
// trailing pad and pad count taken off), which are exactly io::to_cdr's, and the message decoded from
// them; in process there are no bytes. So run.mcap records the bytes already made over DDS and the
// same bytes encoded once in process. And the QoS a host states where it advertises and subscribes
// is the one the DDS endpoints get.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "dds/dds_transport.hpp"
#include "io/mcap_test_messages.hpp"
#include "io/ros2_cdr.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/messages.hpp"

namespace quadcosim::io {
namespace {

dds::RosEnvironment tap_env() {
  dds::RosEnvironment e;
  e.domain_id = 100 + static_cast<std::uint32_t>((getpid() + 50) % 100);  // apart from other test runs
  e.range = dds::DiscoveryRange::kLocalhost;
  return e;
}

TEST(WireTapTest, OverDdsTheTapGetsTheWritersBytesWhichAreToCdrsForEveryPadding) {
  dds::DdsTransport bus(tap_env());
  // A PlantStatus (strings between 8-byte fields) and a String (ends in its string: Cyclone pads it)
  const std::string status_topic = "/tap_test/plant_status", text_topic = "/tap_test/text";
  std::vector<std::vector<std::uint8_t>> wires, decoded;
  const auto tap = [&]<class T>(const T& m, sim::SenderId, sim::WireBytes wire) {
    wires.emplace_back(wire.begin(), wire.end());
    decoded.push_back(to_cdr(m));
  };
  bus.subscribe_tap<msg::PlantStatus>(status_topic, tap);
  bus.subscribe_tap<msg::String>(text_topic, tap);
  auto status = bus.advertise<msg::PlantStatus>(status_topic);
  auto text = bus.advertise<msg::String>(text_topic);
  ASSERT_TRUE(bus.spin_until(
      [&] { return bus.matched_readers(status_topic) > 0 && bus.matched_readers(text_topic) > 0; }, 5'000'000'000));
  std::set<std::size_t> sizes_mod4;
  const std::vector<std::string> strings = {"", "a", "ab", "abc", "abcd", "world", "odom_xy"};
  std::vector<std::vector<std::uint8_t>> sent;
  for (std::size_t k = 0; k < strings.size(); ++k) {
    msg::PlantStatus m = testing::sample_plant_status(static_cast<int>(k) * 7 + 3);
    m.last_problem = strings[k];
    sent.push_back(to_cdr(m));
    status.publish(m);
    ASSERT_TRUE(bus.spin_until([&] { return wires.size() == sent.size(); }, 5'000'000'000)) << k;
    msg::String t;
    t.data = strings[k];  // every length mod 4: Cyclone pads the sample, to_cdr does not
    sent.push_back(to_cdr(t));
    sizes_mod4.insert(sent.back().size() % 4);
    text.publish(t);
    ASSERT_TRUE(bus.spin_until([&] { return wires.size() == sent.size(); }, 5'000'000'000)) << k;
  }
  EXPECT_EQ(sizes_mod4.size(), 4u) << "every padding case was sent";
  ASSERT_EQ(wires.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(wires[i], sent[i]) << "sample " << i;
    EXPECT_EQ(decoded[i], sent[i]) << "sample " << i << ": the message decoded from the bytes";
  }
}

TEST(WireTapTest, InProcessATapHasNoBytes) {
  sim::InProcessTransport bus;
  int taps = 0;
  bus.subscribe_tap<msg::PlantStatus>("/s", [&](const msg::PlantStatus& m, sim::SenderId s, sim::WireBytes wire) {
    EXPECT_TRUE(wire.empty());
    EXPECT_EQ(s, 0u);
    EXPECT_EQ(m.last_problem, "x");
    ++taps;
  });
  msg::PlantStatus m;
  m.last_problem = "x";
  bus.advertise<msg::PlantStatus>("/s").publish(m);
  EXPECT_EQ(taps, 1);
}

// Transient local, stated where the topic is advertised and subscribed, gives a reader made after the
// publication the sample; the table's QoS for the same kind of topic (the ROS default: volatile) does not.
TEST(TransportQosTest, TheDdsTransportUsesTheQosItIsGiven) {
  dds::DdsTransport bus(tap_env());
  const sim::TopicQos latched{1, true, true};
  ASSERT_FALSE(sim::TopicQos::for_topic("/qos_test/given").transient_local);
  msg::String m;
  m.data = "published before the reader";
  auto given = bus.advertise<msg::String>("/qos_test/given", latched);
  auto table = bus.advertise<msg::String>("/qos_test/table");
  given.publish(m);
  table.publish(m);
  std::vector<std::string> got_given, got_table;
  bus.subscribe<msg::String>(
      "/qos_test/given", [&](const msg::String& s) { got_given.push_back(s.data); }, latched);
  bus.subscribe<msg::String>("/qos_test/table", [&](const msg::String& s) { got_table.push_back(s.data); });
  ASSERT_TRUE(bus.spin_until([&] { return !got_given.empty(); }, 5'000'000'000));
  EXPECT_EQ(got_given, std::vector<std::string>{m.data});
  bus.spin_until([] { return false; }, 300'000'000);  // time for a sample that must not come
  EXPECT_TRUE(got_table.empty());
}

}  // namespace
}  // namespace quadcosim::io
