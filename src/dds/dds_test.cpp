// DDS transport tests on a private domain with localhost-only discovery.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <unistd.h>

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
