// DDS transport tests on a private domain with localhost-only discovery.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "dds/arrival_executor.hpp"
#include "dds/dds_transport.hpp"
#include "sim/messages.hpp"

namespace quadcosim::dds {
namespace {

RosEnvironment test_env() {
  RosEnvironment e;
  e.domain_id = 100 + static_cast<std::uint32_t>(getpid() % 100);  // apart from other test runs
  e.range = DiscoveryRange::kLocalhost;
  return e;
}

TEST(DdsTransportTest, RoundTripsEveryMessageTypeFieldForField) {
  DdsTransport a(test_env()), b(test_env());
  msg::PoseStamped pose_in;
  msg::Imu imu_in;
  msg::Float64MultiArray cmd_in;
  msg::ControllerStatus status_in;
  int got = 0;
  b.subscribe<msg::PoseStamped>("/t/Pose", [&](const msg::PoseStamped& m) { pose_in = m; ++got; });
  b.subscribe<msg::Imu>("/t/Imu", [&](const msg::Imu& m) { imu_in = m; ++got; });
  b.subscribe<msg::Float64MultiArray>("/t/cmd", [&](const msg::Float64MultiArray& m) { cmd_in = m; ++got; });
  b.subscribe<msg::ControllerStatus>("/t/status", [&](const msg::ControllerStatus& m) { status_in = m; ++got; });
  auto pose = a.advertise<msg::PoseStamped>("/t/Pose");
  auto imu = a.advertise<msg::Imu>("/t/Imu");
  auto cmd = a.advertise<msg::Float64MultiArray>("/t/cmd");
  auto status = a.advertise<msg::ControllerStatus>("/t/status");
  ASSERT_TRUE(b.spin_until([&] { return b.matched_writers("/t/Pose") == 1 && b.matched_writers("/t/status") == 1; },
                           5'000'000'000));
  ASSERT_TRUE(a.spin_until([&] { return a.matched_readers("/t/cmd") == 1; }, 5'000'000'000));

  msg::PoseStamped p;
  p.header = {{12, 345}, "world"};
  p.position = {1.5, -2.25, 1e-300};
  p.orientation = {0.1, 0.2, 0.3, 0.9};
  msg::Imu i;
  i.header = {{1, 2}, "base_link"};
  i.orientation_covariance[8] = 7.0;
  i.linear_acceleration = {0.0, -0.0, 9.81};
  msg::Float64MultiArray c;
  c.data = {4830.5, 1.0 / 3.0, 0.0, 1e9};
  c.dim = {{"rotors@5", 4, 4}};
  msg::ControllerStatus s;
  s.header.stamp = {3, 4};
  s.mode = "position";
  s.setpoint = {1, 2, 3, 0.1, 0.2, 0.3};
  s.rotor_saturated = {true, false, true, false};
  s.safety = true;
  pose.publish(p);
  imu.publish(i);
  cmd.publish(c);
  status.publish(s);
  ASSERT_TRUE(b.spin_until([&] { return got == 4; }, 5'000'000'000));

  EXPECT_EQ(pose_in.header.stamp.sec, 12);
  EXPECT_EQ(pose_in.header.stamp.nanosec, 345u);
  EXPECT_EQ(pose_in.header.frame_id, "world");
  EXPECT_EQ(pose_in.position.x, 1.5);
  EXPECT_EQ(pose_in.position.z, 1e-300);
  EXPECT_EQ(pose_in.orientation.w, 0.9);
  EXPECT_EQ(imu_in.header.frame_id, "base_link");
  EXPECT_EQ(imu_in.orientation_covariance[8], 7.0);
  EXPECT_TRUE(std::signbit(imu_in.linear_acceleration.y));
  EXPECT_EQ(cmd_in.data, c.data);
  ASSERT_EQ(cmd_in.dim.size(), 1u);
  EXPECT_EQ(cmd_in.dim[0].label, "rotors@5");
  EXPECT_EQ(msg::command_stamp_ns(cmd_in), 5);
  EXPECT_EQ(status_in.mode, "position");
  EXPECT_EQ(status_in.setpoint, s.setpoint);
  EXPECT_EQ(status_in.rotor_saturated, s.rotor_saturated);
  EXPECT_TRUE(status_in.safety);
}

// The types the test above leaves out, and every field of the two status types, each with a value
// of its own so a field read from or written to its neighbour shows.
TEST(DdsTransportTest, RoundTripsTheRestFieldForField) {
  DdsTransport a(test_env()), b(test_env());
  msg::TwistStamped twist_in;
  msg::Clock clock_in;
  msg::ControllerStatus cs_in;
  msg::PlantStatus ps_in;
  int got = 0;
  b.subscribe<msg::TwistStamped>("/r/Velocity", [&](const msg::TwistStamped& m) { twist_in = m; ++got; });
  b.subscribe<msg::Clock>("/r/clock", [&](const msg::Clock& m) { clock_in = m; ++got; });
  b.subscribe<msg::ControllerStatus>("/r/cs", [&](const msg::ControllerStatus& m) { cs_in = m; ++got; });
  b.subscribe<msg::PlantStatus>("/r/ps", [&](const msg::PlantStatus& m) { ps_in = m; ++got; });
  auto twist = a.advertise<msg::TwistStamped>("/r/Velocity");
  auto clock = a.advertise<msg::Clock>("/r/clock");
  auto cs = a.advertise<msg::ControllerStatus>("/r/cs");
  auto ps = a.advertise<msg::PlantStatus>("/r/ps");
  ASSERT_TRUE(b.spin_until([&] { return b.matched_writers("/r/Velocity") == 1 && b.matched_writers("/r/clock") == 1 &&
                                        b.matched_writers("/r/cs") == 1 && b.matched_writers("/r/ps") == 1; },
                           5'000'000'000));
  ASSERT_TRUE(a.spin_until([&] { return a.matched_readers("/r/ps") == 1; }, 5'000'000'000));

  msg::TwistStamped t;
  t.header = {{7, 8}, "world"};
  t.linear = {1, 2, 3};
  t.angular = {4, 5, 6};
  msg::Clock k;
  k.clock = {2147483647, 999999999};
  msg::ControllerStatus c;
  c.header = {{9, 10}, "base_link"};
  c.mode = "attitude";
  c.setpoint = {1, 2, 3, 4, 5, 6};
  c.u = {7, 8, 9, 10};
  c.error = {11, 12, 13, 14};
  c.rotor_saturated = {false, true, false, true};
  c.tilt_saturated = true;
  c.safety = false;
  c.rejected_non_finite = 101;
  c.rejected_bad_quaternion = 102;
  c.rejected_bad_stamp = 103;
  c.rejected_stamp_backwards = 18446744073709551615u;
  msg::PlantStatus p;
  p.header = {{11, 12}, ""};
  p.commands_accepted = 201;
  p.commands_clamped = 202;
  p.commands_rejected_length = 203;
  p.commands_rejected_non_finite = 204;
  p.last_problem = "speed 1e+09 rad/s above omega_max";
  p.watchdog_active = true;
  p.watchdog_trips = 205;
  p.watchdog_ticks = 206;
  twist.publish(t);
  clock.publish(k);
  cs.publish(c);
  ps.publish(p);
  ASSERT_TRUE(b.spin_until([&] { return got == 4; }, 5'000'000'000));

  EXPECT_EQ(twist_in.header.stamp.to_ns(), t.header.stamp.to_ns());
  EXPECT_EQ(twist_in.header.frame_id, "world");
  EXPECT_EQ(twist_in.linear.x, 1);
  EXPECT_EQ(twist_in.linear.z, 3);
  EXPECT_EQ(twist_in.angular.x, 4);
  EXPECT_EQ(twist_in.angular.z, 6);
  EXPECT_EQ(clock_in.clock.sec, 2147483647);
  EXPECT_EQ(clock_in.clock.nanosec, 999999999u);
  EXPECT_EQ(cs_in.header.frame_id, "base_link");
  EXPECT_EQ(cs_in.header.stamp.to_ns(), c.header.stamp.to_ns());
  EXPECT_EQ(cs_in.mode, "attitude");
  EXPECT_EQ(cs_in.setpoint, c.setpoint);
  EXPECT_EQ(cs_in.u, c.u);
  EXPECT_EQ(cs_in.error, c.error);
  EXPECT_EQ(cs_in.rotor_saturated, c.rotor_saturated);
  EXPECT_TRUE(cs_in.tilt_saturated);
  EXPECT_FALSE(cs_in.safety);
  EXPECT_EQ(cs_in.rejected_non_finite, 101u);
  EXPECT_EQ(cs_in.rejected_bad_quaternion, 102u);
  EXPECT_EQ(cs_in.rejected_bad_stamp, 103u);
  EXPECT_EQ(cs_in.rejected_stamp_backwards, 18446744073709551615u);
  EXPECT_EQ(ps_in.header.stamp.to_ns(), p.header.stamp.to_ns());
  EXPECT_EQ(ps_in.commands_accepted, 201u);
  EXPECT_EQ(ps_in.commands_clamped, 202u);
  EXPECT_EQ(ps_in.commands_rejected_length, 203u);
  EXPECT_EQ(ps_in.commands_rejected_non_finite, 204u);
  EXPECT_EQ(ps_in.last_problem, p.last_problem);
  EXPECT_TRUE(ps_in.watchdog_active);
  EXPECT_EQ(ps_in.watchdog_trips, 205u);
  EXPECT_EQ(ps_in.watchdog_ticks, 206u);
}

// Waits (without spinning `t`) until `done()`, up to 5 s.
template <class F>
bool eventually(F done) {
  for (int i = 0; i < 5000 && !done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return done();
}

msg::Clock clock_at(std::int64_t ns) {
  msg::Clock c;
  c.clock = msg::Time::from_ns(ns);
  return c;
}

// Two transports on one domain: `a` publishes /t/in, `b` subscribes (matched before returning).
struct ArrivalRig {
  DdsTransport a{test_env()}, b{test_env()};
  sim::Publisher<msg::Clock> in;
  std::vector<std::int64_t> got;
  std::vector<std::thread::id> threads;
  std::atomic<int> count{0};

  explicit ArrivalRig(std::function<void(const msg::Clock&)> extra = {}) {
    b.subscribe<msg::Clock>("/t/in", [this, extra](const msg::Clock& m) {
      got.push_back(m.clock.to_ns());
      threads.push_back(std::this_thread::get_id());
      if (extra) extra(m);
      ++count;
    });
    in = a.advertise<msg::Clock>("/t/in");
  }
  bool matched() {
    return b.spin_until([&] { return b.matched_writers("/t/in") == 1; }, 5'000'000'000) &&
           a.spin_until([&] { return a.matched_readers("/t/in") == 1; }, 5'000'000'000);
  }
};

TEST(DdsTransportTest, OnArrivalOnlyTheOwningThreadMayWaitAndTheTransportItselfNotSpin) {
  ArrivalRig rig;
  ArrivalExecutor arrival(rig.b);
  std::string error;
  std::thread other([&] {
    try {
      arrival.wait(0);
    } catch (const std::logic_error& e) {
      error = e.what();
    }
  });
  other.join();
  EXPECT_NE(error.find("ArrivalExecutor::wait"), std::string::npos) << error;
  EXPECT_EQ(arrival.wait(0), 0);  // the owner may
  EXPECT_THROW(rig.b.spin_once(0), std::logic_error);  // not past the executor
  EXPECT_THROW(ArrivalExecutor second(rig.b), std::logic_error);
}

// In one process Cyclone delivers to a local reader on the publishing thread, so a publisher on a
// thread of its own stands for the receive thread of a remote one.
TEST(DdsTransportTest, OnArrivalDeliversInOrderOnlyWhileTheOwnerWaits) {
  ArrivalRig rig;
  ASSERT_TRUE(rig.matched());
  auto arrival = std::make_unique<ArrivalExecutor>(rig.b);
  std::thread first([&] {
    for (int i = 1; i <= 50; ++i) rig.in.publish(clock_at(i));
  });
  int counted = 0;  // what wait reports as delivered since its last call
  const auto t0 = std::chrono::steady_clock::now();
  while (rig.count < 50 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    counted += arrival->wait(10'000'000);
  }
  first.join();
  counted += arrival->wait(0);
  EXPECT_EQ(counted, 50);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(rig.got[static_cast<std::size_t>(i)], i + 1);
  for (const auto& id : rig.threads) EXPECT_NE(id, std::this_thread::get_id());
  // Between waits the owner holds the deliveries: the other thread's sample waits.
  std::thread second([&] { rig.in.publish(clock_at(51)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(rig.count, 50);
  ASSERT_TRUE(arrival->wait_until([&] { return rig.count == 51; }, 5'000'000'000));
  second.join();

  arrival.reset();  // back to delivery by spin_once, on the caller's thread
  std::thread third([&] { rig.in.publish(clock_at(52)); });
  third.join();
  EXPECT_EQ(rig.count, 51);
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.count == 52; }, 5'000'000'000));
  EXPECT_EQ(rig.threads.back(), std::this_thread::get_id());
  EXPECT_EQ(rig.got.back(), 52);
}

TEST(DdsTransportTest, OnArrivalADeliveryMayPublishToItsOwnTransport) {
  // b answers every /t/in on /t/echo, which b itself also reads: a delivery inside a delivery.
  std::atomic<int> echoes{0};
  sim::Publisher<msg::Clock> echo;
  ArrivalRig rig([&](const msg::Clock& m) { echo.publish(m); });
  echo = rig.b.advertise<msg::Clock>("/t/echo");
  rig.b.subscribe<msg::Clock>("/t/echo", [&](const msg::Clock&) { ++echoes; });
  ASSERT_TRUE(rig.matched());
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.b.matched_readers("/t/echo") >= 1; }, 5'000'000'000));
  ArrivalExecutor arrival(rig.b);
  std::thread publisher([&] {
    for (int i = 1; i <= 20; ++i) rig.in.publish(clock_at(i));
  });
  EXPECT_TRUE(arrival.wait_until([&] { return echoes == 20; }, 5'000'000'000)) << echoes << " echoes";
  publisher.join();
}

TEST(DdsTransportTest, OnArrivalAFailedDeliveryWakesTheWaitAndIsRethrown) {
  ArrivalRig rig([](const msg::Clock& m) {
    if (m.clock.to_ns() == 3) throw std::invalid_argument("sample 3 refused");
  });
  ASSERT_TRUE(rig.matched());
  ArrivalExecutor arrival(rig.b);
  for (int i = 1; i <= 5; ++i) rig.in.publish(clock_at(i));
  const auto t0 = std::chrono::steady_clock::now();
  try {
    for (int i = 0; i < 100; ++i) arrival.wait(10'000'000'000);
    FAIL() << "not rethrown";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "sample 3 refused");
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));  // woken, not timed out
  EXPECT_EQ(rig.count, 2);  // 1 and 2; nothing after the failure
}

TEST(DdsTransportTest, OnArrivalTheHookRunsAfterEachDeliveryAndTrueEndsTheWait) {
  ArrivalRig rig;
  ASSERT_TRUE(rig.matched());
  ArrivalExecutor arrival(rig.b);
  int runs = 0;
  arrival.after_each([&] {
    ++runs;
    return !rig.got.empty() && rig.got.back() == 7;
  });
  std::thread publisher([&] {
    for (int i = 1; i <= 7; ++i) rig.in.publish(clock_at(i));
  });
  const auto t0 = std::chrono::steady_clock::now();
  // Long waits return once sample 7 is in (every earlier one delivered before it).
  while (rig.count < 7 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    arrival.wait(30'000'000'000);
  }
  publisher.join();
  EXPECT_EQ(rig.count, 7);
  EXPECT_EQ(runs, 7);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  // wait_until runs the hook too, beside its own condition.
  std::thread more([&] { rig.in.publish(clock_at(8)); });
  EXPECT_TRUE(arrival.wait_until([&] { return rig.count == 8; }, 5'000'000'000));
  more.join();
  EXPECT_EQ(runs, 8);
}

TEST(DdsTransportTest, TopicAndTypeNamesFollowRos2) {
  EXPECT_EQ(dds_topic_name("/drone/Pose"), "rt/drone/Pose");
  EXPECT_STREQ(type_ops(typeid(msg::PoseStamped))->descriptor->m_typename,
               "geometry_msgs::msg::dds_::PoseStamped_");
  EXPECT_STREQ(type_ops(typeid(msg::Imu))->descriptor->m_typename, "sensor_msgs::msg::dds_::Imu_");
  EXPECT_STREQ(type_ops(typeid(msg::Float64MultiArray))->descriptor->m_typename,
               "std_msgs::msg::dds_::Float64MultiArray_");
  EXPECT_STREQ(type_ops(typeid(msg::Clock))->descriptor->m_typename, "rosgraph_msgs::msg::dds_::Clock_");
}

TEST(RosEnvironmentTest, ReadsDomainAndRange) {
  setenv("ROS_DOMAIN_ID", "0x10", 1);
  setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST", 1);
  unsetenv("ROS_LOCALHOST_ONLY");
  setenv("ROS_STATIC_PEERS", "10.0.0.2;host.example", 1);
  const RosEnvironment e = read_ros_environment();
  EXPECT_EQ(e.domain_id, 16u);
  EXPECT_EQ(e.range, DiscoveryRange::kLocalhost);
  const std::string xml = cyclone_config(e);
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"localhost\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"10.0.0.2\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"host.example\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"), std::string::npos);

  setenv("ROS_DOMAIN_ID", "500", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  setenv("ROS_DOMAIN_ID", "12abc", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  setenv("ROS_DOMAIN_ID", "", 1);
  setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "NEARBY", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  unsetenv("ROS_AUTOMATIC_DISCOVERY_RANGE");
  setenv("ROS_LOCALHOST_ONLY", "1", 1);
  EXPECT_EQ(read_ros_environment().range, DiscoveryRange::kLocalhost);
  EXPECT_EQ(read_ros_environment().domain_id, 0u);
  unsetenv("ROS_LOCALHOST_ONLY");
  unsetenv("ROS_STATIC_PEERS");
  unsetenv("ROS_DOMAIN_ID");
}

}  // namespace
}  // namespace quadcosim::dds

#include "dds/node_announcer.hpp"
#include "rmw_dds_common.h"

namespace quadcosim::dds {
namespace {

TEST(NodeAnnouncerTest, PublishesTheNodeWithItsEndpointGids) {
  DdsTransport node(test_env());
  auto pub = node.advertise<msg::PoseStamped>("/n/Pose");
  node.subscribe<msg::Clock>("/clock_n", [](const msg::Clock&) {});
  NodeAnnouncer announcer(node.participant().handle(), "quadrotor_plant");
  announcer.announce();
  EXPECT_EQ(announcer.writers(), 1u);
  EXPECT_EQ(announcer.readers(), 1u);

  // A late-joining reader of ros_discovery_info (transient local) still gets it.
  Participant other(test_env());
  const dds_entity_t topic = dds_create_topic(other.handle(), &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                              "ros_discovery_info", nullptr, nullptr);
  ASSERT_GT(topic, 0);
  dds_qos_t* qos = ros_qos(100, true);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t reader = dds_create_reader(other.handle(), topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(reader, 0);
  dds_guid_t participant_guid;
  ASSERT_EQ(dds_get_guid(node.participant().handle(), &participant_guid), DDS_RETCODE_OK);

  bool found = false;
  for (int attempt = 0; attempt < 100 && !found; ++attempt) {
    const dds_entity_t ws = dds_create_waitset(other.handle());
    const dds_entity_t rc = dds_create_readcondition(reader, DDS_ANY_STATE);
    dds_waitset_attach(ws, rc, 0);
    dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(100));
    void* samples[8] = {nullptr};
    dds_sample_info_t infos[8];
    const dds_return_t n = dds_take(reader, samples, infos, 8, 8);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* info = static_cast<const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_*>(samples[i]);
      if (std::memcmp(info->gid.data, participant_guid.v, 16) != 0) continue;
      ASSERT_EQ(info->node_entities_info_seq._length, 1u);
      const auto& n0 = info->node_entities_info_seq._buffer[0];
      EXPECT_STREQ(n0.node_name, "quadrotor_plant");
      EXPECT_STREQ(n0.node_namespace, "/");
      EXPECT_EQ(n0.reader_gid_seq._length, 1u);
      EXPECT_EQ(n0.writer_gid_seq._length, 1u);
      found = true;
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    dds_delete(ws);
  }
  EXPECT_TRUE(found);
}

TEST(ParticipantTest, UserDataSaysEnclave) {
  Participant p(test_env());
  dds_qos_t* qos = dds_create_qos();
  ASSERT_EQ(dds_get_qos(p.handle(), qos), DDS_RETCODE_OK);
  void* data = nullptr;
  size_t size = 0;
  ASSERT_TRUE(dds_qget_userdata(qos, &data, &size));
  EXPECT_EQ(std::string(static_cast<char*>(data), size), "enclave=/;");
  dds_free(data);
  dds_delete_qos(qos);
}

}  // namespace
}  // namespace quadcosim::dds

#include "dds/graph.hpp"
#include "dds/topic_tools.hpp"

namespace quadcosim::dds {
namespace {

TEST(GraphTest, DemanglesRosTypesAsRmwCyclonedds) {
  EXPECT_EQ(demangle_ros_type("geometry_msgs::msg::dds_::PoseStamped_"), "geometry_msgs/msg/PoseStamped");
  EXPECT_EQ(demangle_ros_type("sensor_msgs::msg::dds_::Imu_"), "sensor_msgs/msg/Imu");
  EXPECT_EQ(demangle_ros_type("rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"),
            "rmw_dds_common/msg/ParticipantEntitiesInfo");
  EXPECT_EQ(demangle_ros_type("rcl_interfaces::srv::dds_::SetParameters_Request_"),
            "rcl_interfaces/srv/SetParameters_Request");
  // Not mangled ROS types: unchanged.
  EXPECT_EQ(demangle_ros_type("HelloWorldData::Msg"), "HelloWorldData::Msg");
  EXPECT_EQ(demangle_ros_type("pkg::msg::dds_::Name"), "pkg::msg::dds_::Name");
  EXPECT_EQ(demangle_ros_type(""), "");
  // Every type quadcosim writes demangles to its ROS name.
  EXPECT_EQ(demangle_ros_type(type_ops(typeid(msg::ControllerStatus))->descriptor->m_typename),
            msg::ControllerStatus::kRosType);
  EXPECT_EQ(demangle_ros_type(type_ops(typeid(msg::Float64MultiArray))->descriptor->m_typename),
            msg::Float64MultiArray::kRosType);
}

TEST(GraphTest, OnlyRtTopicsAreRosTopics) {
  EXPECT_EQ(ros_topic_name("rt/drone/Pose"), "/drone/Pose");
  EXPECT_EQ(ros_topic_name("rt/clock"), "/clock");
  EXPECT_EQ(ros_topic_name("ros_discovery_info"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rq/attitude_controller/set_parametersRequest"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rt/"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rtx/a"), std::nullopt);
  EXPECT_TRUE(is_hidden_topic("/_secret"));
  EXPECT_TRUE(is_hidden_topic("/drone/_debug/x"));
  EXPECT_FALSE(is_hidden_topic("/drone/motor_commands"));
}

TEST(GraphTest, ListsTopicsSortedUniqueWithTypes) {
  const std::vector<Endpoint> endpoints = {
      {"rt/drone/Pose", "geometry_msgs::msg::dds_::PoseStamped_", true, true},
      {"rt/clock", "rosgraph_msgs::msg::dds_::Clock_", true, false},
      {"ros_discovery_info", "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_", true, true},
      {"rt/drone/Pose", "geometry_msgs::msg::dds_::PoseStamped_", false, true},
      {"rt/drone/Imu", "sensor_msgs::msg::dds_::Imu_", true, true},
      {"rt/drone/_internal", "std_msgs::msg::dds_::Float64MultiArray_", true, true},
      {"rt/mixed", "b::msg::dds_::B_", true, true},
      {"rt/mixed", "a::msg::dds_::A_", false, true},
      {"rq/x/get_parametersRequest", "rcl_interfaces::srv::dds_::GetParameters_Request_", true, true},
  };
  const auto topics = ros_topics(endpoints);
  ASSERT_EQ(topics.size(), 5u);
  EXPECT_EQ(topics[0].name, "/clock");
  EXPECT_EQ(topics[0].best_effort_publishers, 1);
  EXPECT_EQ(topics[2].name, "/drone/Pose");
  EXPECT_EQ(topics[2].publishers, 1);
  EXPECT_EQ(topics[2].subscribers, 1);
  EXPECT_EQ(format_topic_list(topics, false), "/clock\n/drone/Imu\n/drone/Pose\n/mixed\n");
  EXPECT_EQ(format_topic_list(topics, true),
            "/clock [rosgraph_msgs/msg/Clock]\n"
            "/drone/Imu [sensor_msgs/msg/Imu]\n"
            "/drone/Pose [geometry_msgs/msg/PoseStamped]\n"
            "/mixed [a/msg/A, b/msg/B]\n");
  EXPECT_EQ(format_topic_list(topics, false, true), "/clock\n/drone/Imu\n/drone/Pose\n/drone/_internal\n/mixed\n");
  EXPECT_EQ(format_topic_list({}, true), "");
}

TEST(GraphTest, DiscoversAnotherParticipantsEndpoints) {
  DdsTransport node(test_env());
  auto pub = node.advertise<msg::PoseStamped>("/g/Pose");
  node.set_qos("/g/Imu", QosProfile::sensor_data());
  node.subscribe<msg::Imu>("/g/Imu", [](const msg::Imu&) {});
  Participant tool(test_env());
  auto has_both = [](const std::vector<Endpoint>& es) {
    int n = 0;
    for (const auto& e : es) n += (e.dds_topic == "rt/g/Pose" && e.writer) + (e.dds_topic == "rt/g/Imu" && !e.writer);
    return n == 2;
  };
  const auto es = discover_endpoints(tool.handle(), DDS_SECS(10), has_both);
  ASSERT_TRUE(has_both(es));
  for (const auto& e : es) {
    if (e.dds_topic == "rt/g/Pose") {
      EXPECT_EQ(e.dds_type, "geometry_msgs::msg::dds_::PoseStamped_");
      EXPECT_TRUE(e.reliable);
    }
    if (e.dds_topic == "rt/g/Imu") {
      EXPECT_FALSE(e.reliable);
    }
  }
  // The participant's own endpoints are not listed.
  for (const auto& e : discover_endpoints(node.participant().handle(), DDS_MSECS(200))) {
    EXPECT_NE(e.dds_topic, "rt/g/Pose");
  }
  // Without `done`, it waits out the whole time.
  const auto t0 = dds_time();
  discover_endpoints(tool.handle(), DDS_MSECS(300));
  EXPECT_GE(dds_time() - t0, DDS_MSECS(290));
}

TEST(TopicToolsTest, FloatsAsPythonReprThroughPyYaml) {
  EXPECT_EQ(yaml_float(0.0), "0.0");
  EXPECT_EQ(yaml_float(-0.0), "-0.0");
  EXPECT_EQ(yaml_float(1.0), "1.0");
  EXPECT_EQ(yaml_float(0.1), "0.1");
  EXPECT_EQ(yaml_float(-9.81), "-9.81");
  EXPECT_EQ(yaml_float(0.0001), "0.0001");
  EXPECT_EQ(yaml_float(0.00001), "1.0e-05");
  EXPECT_EQ(yaml_float(1.5e-7), "1.5e-07");
  EXPECT_EQ(yaml_float(1e-300), "1.0e-300");
  EXPECT_EQ(yaml_float(1e15), "1000000000000000.0");
  EXPECT_EQ(yaml_float(1e16), "1.0e+16");
  EXPECT_EQ(yaml_float(123456.789), "123456.789");
  EXPECT_EQ(yaml_float(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(yaml_float(std::nan("")), ".nan");
  EXPECT_EQ(yaml_float(INFINITY), ".inf");
  EXPECT_EQ(yaml_float(-INFINITY), "-.inf");
}

TEST(TopicToolsTest, StringsQuotedOnlyWhenNeeded) {
  EXPECT_EQ(yaml_string("world"), "world");
  EXPECT_EQ(yaml_string("rotors@100000000"), "rotors@100000000");
  EXPECT_EQ(yaml_string("it's"), "it's");
  EXPECT_EQ(yaml_string(""), "''");
  EXPECT_EQ(yaml_string("123"), "'123'");
  EXPECT_EQ(yaml_string("1.5"), "'1.5'");
  EXPECT_EQ(yaml_string("true"), "'true'");
  EXPECT_EQ(yaml_string("null"), "'null'");
  EXPECT_EQ(yaml_string("a: b"), "'a: b'");
  EXPECT_EQ(yaml_string("'q'"), "'''q'''");
  EXPECT_EQ(yaml_string("@x"), "'@x'");
  EXPECT_EQ(yaml_string("a\nb"), "\"a\\nb\"");
}

TEST(TopicToolsTest, MessagesAsRos2TopicEcho) {
  msg::PoseStamped p;
  p.header.stamp = {12, 345};
  p.header.frame_id = "world";
  p.position = {1.5, 0.0, -2.0};
  EXPECT_EQ(to_yaml(p),
            "header:\n"
            "  stamp:\n"
            "    sec: 12\n"
            "    nanosec: 345\n"
            "  frame_id: world\n"
            "pose:\n"
            "  position:\n"
            "    x: 1.5\n"
            "    y: 0.0\n"
            "    z: -2.0\n"
            "  orientation:\n"
            "    x: 0.0\n"
            "    y: 0.0\n"
            "    z: 0.0\n"
            "    w: 1.0\n");

  msg::Float64MultiArray c;
  c.data = {400.0, 400.5};
  c.dim = {{"rotors@10000000", 4, 4}};
  EXPECT_EQ(to_yaml(c),
            "layout:\n"
            "  dim:\n"
            "  - label: rotors@10000000\n"
            "    size: 4\n"
            "    stride: 4\n"
            "  data_offset: 0\n"
            "data:\n"
            "- 400.0\n"
            "- 400.5\n");
  EXPECT_EQ(to_yaml(msg::Float64MultiArray{}), "layout:\n  dim: []\n  data_offset: 0\ndata: []\n");

  msg::Clock k;
  k.clock = {3, 10000000};
  EXPECT_EQ(to_yaml(k), "clock:\n  sec: 3\n  nanosec: 10000000\n");

  msg::Imu imu;
  imu.header.frame_id = "base_link";
  const std::string y = to_yaml(imu);
  EXPECT_NE(y.find("  frame_id: base_link\norientation:\n  x: 0.0\n"), std::string::npos);
  EXPECT_NE(y.find("orientation_covariance:\n- 0.0\n- 0.0\n"), std::string::npos);
  EXPECT_NE(y.find("\nlinear_acceleration_covariance:\n- 0.0\n"), std::string::npos);

  msg::ControllerStatus s;
  s.mode = "attitude";
  s.rotor_saturated[1] = true;
  const std::string sy = to_yaml(s);
  EXPECT_NE(sy.find("mode: attitude\nsetpoint:\n- 0.0\n"), std::string::npos);
  EXPECT_NE(sy.find("rotor_saturated:\n- false\n- true\n- false\n- false\ntilt_saturated: false\nsafety: false\n"),
            std::string::npos);
  EXPECT_NE(to_yaml(msg::TwistStamped{}).find("twist:\n  linear:\n    x: 0.0\n"), std::string::npos);
}

TEST(TopicToolsTest, RateWindowAsRos2TopicHz) {
  RateWindow w(3);
  EXPECT_FALSE(w.stats());
  w.add(0);
  EXPECT_FALSE(w.stats());
  w.add(10'000'000);
  w.add(20'000'000);
  w.add(32'000'000);
  w.add(40'000'000);  // the window keeps the last 3 intervals: 10, 12, 8 ms
  const auto s = w.stats();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->window, 3u);
  EXPECT_NEAR(s->rate_hz, 100.0, 1e-9);
  EXPECT_NEAR(s->min_s, 0.008, 1e-12);
  EXPECT_NEAR(s->max_s, 0.012, 1e-12);
  EXPECT_NEAR(s->std_dev_s, std::sqrt(8.0 / 3.0) * 1e-3, 1e-12);
  EXPECT_EQ(w.messages(), 5u);
  EXPECT_EQ(format_rate(*s), "average rate: 100.000\n\tmin: 0.008s max: 0.012s std dev: 0.00163s window: 3\n");
  w.add(1'000);  // the clock went back: start over
  EXPECT_FALSE(w.stats());
}

}  // namespace
}  // namespace quadcosim::dds
